//! STL files (binary or ASCII) as triangle meshes, for `"type": "stl"` surfaces.
//!
//! Reading uses the `stl_io` crate, with two fixes around its format detection: `stl_io`
//! takes any file whose first line starts with `solid ` for ASCII, but many CAD exporters write
//! binary files whose 80-byte header starts with `solid` too; and it rejects ASCII files whose
//! first line is a bare `solid`. So kerf decides itself: a file whose size is exactly
//! `84 + 50 n` for the facet count `n` in its header is binary; otherwise a file starting with
//! `solid` is ASCII.
//!
//! Vertices shared between facets are merged (bit-identical coordinates), facets with two
//! coinciding corners are dropped (they have no normal; the count is kept), and a mesh with a
//! non-finite vertex, no facets or only zero-area facets is refused.

use std::io::Cursor;
use std::path::Path;

use nalgebra::Point3;

use crate::error::StlProblem;

/// A triangle mesh read from an STL file.
#[derive(Debug, Clone, PartialEq)]
pub struct StlMesh {
    /// Distinct vertices, in mm (STL stores `f32`; widened exactly).
    pub vertices: Vec<Point3<f64>>,
    /// Vertex indices of each kept facet, in file order, with the file's winding.
    pub triangles: Vec<[u32; 3]>,
    /// Facets dropped because two of their corners coincide.
    pub dropped_facets: usize,
}

/// Reads a binary or ASCII STL file. It is named inside a curves file, so it must be a regular
/// file ([`kerf_io::read_regular_file`]): a FIFO or device path is refused without waiting on
/// it or reading it.
///
/// # Errors
/// [`StlProblem::Read`] if the file is not a regular file, cannot be read or is larger than
/// [`kerf_io::MAX_INPUT_BYTES`], else as [`parse`].
pub fn read(path: &Path) -> Result<StlMesh, StlProblem> {
    let bytes = kerf_io::read_regular_file(path).map_err(|error| StlProblem::Read { error })?;
    parse(bytes)
}

/// Parses the bytes of a binary or ASCII STL file.
///
/// # Errors
/// [`StlProblem::Malformed`] if the bytes are neither a complete binary STL nor a parsable
/// ASCII one, [`StlProblem::NonFiniteVertex`], [`StlProblem::NoFacets`],
/// [`StlProblem::AllDegenerate`] or [`StlProblem::TooManyVertices`].
pub fn parse(mut bytes: Vec<u8>) -> Result<StlMesh, StlProblem> {
    let declared = (bytes.len() >= 84).then(|| {
        84 + 50
            * u64::from(u32::from_le_bytes([
                bytes[80], bytes[81], bytes[82], bytes[83],
            ]))
    });
    let len = bytes.len() as u64;
    let first_line_end = bytes
        .iter()
        .position(|&b| b == b'\n')
        .unwrap_or(bytes.len());
    let starts_solid = bytes[..first_line_end]
        .trim_ascii_start()
        .starts_with(b"solid");
    let binary = match declared {
        Some(size) if size == len => true,
        // Some exporters pad binary files; accept trailing bytes unless it looks like ASCII.
        Some(size) if size < len => !starts_solid,
        _ => false,
    };
    if binary {
        // Hide a "solid" header from stl_io's ASCII probe; the header carries no data.
        bytes[0] = 0;
    } else if starts_solid {
        // stl_io needs the first line to start with "solid " (with a space).
        bytes.splice(..first_line_end, b"solid kerf".iter().copied());
    } else {
        return Err(StlProblem::Malformed {
            reason: match declared {
                None => format!(
                    "{len} bytes: too short for a binary STL (at least 84 bytes) and not ASCII (no \"solid\" at the start)"
                ),
                Some(size) => format!(
                    "binary header declares {} facets ({size} bytes) but the file has {len} bytes",
                    (size - 84) / 50
                ),
            },
        });
    }
    let mut cursor = Cursor::new(bytes);
    let mesh = stl_io::create_stl_reader(&mut cursor)
        .and_then(|mut reader| reader.as_indexed_triangles())
        .map_err(|e| StlProblem::Malformed {
            reason: e.to_string(),
        })?;
    if mesh.faces.is_empty() {
        return Err(StlProblem::NoFacets);
    }
    for (facet, face) in mesh.faces.iter().enumerate() {
        for &v in &face.vertices {
            let [x, y, z] = mesh.vertices[v].0;
            if !(x.is_finite() && y.is_finite() && z.is_finite()) {
                return Err(StlProblem::NonFiniteVertex { facet, x, y, z });
            }
        }
    }
    if u32::try_from(mesh.vertices.len()).is_err() {
        return Err(StlProblem::TooManyVertices {
            count: mesh.vertices.len(),
        });
    }
    let vertices: Vec<Point3<f64>> = mesh
        .vertices
        .iter()
        .map(|v| Point3::new(f64::from(v.0[0]), f64::from(v.0[1]), f64::from(v.0[2])))
        .collect();
    let mut triangles = Vec::with_capacity(mesh.faces.len());
    let mut any_area = false;
    for face in &mesh.faces {
        let [a, b, c] = face.vertices;
        if a == b || b == c || a == c {
            continue;
        }
        any_area |= (vertices[b] - vertices[a])
            .cross(&(vertices[c] - vertices[a]))
            .norm()
            > 0.0;
        // The vertex count fits in u32 (checked above), so every index does.
        triangles.push([a as u32, b as u32, c as u32]);
    }
    if !any_area {
        return Err(StlProblem::AllDegenerate);
    }
    Ok(StlMesh {
        dropped_facets: mesh.faces.len() - triangles.len(),
        vertices,
        triangles,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A unit tetrahedron as STL triangles, outward winding.
    fn tetrahedron() -> Vec<stl_io::Triangle> {
        let p = [
            [0.0, 0.0, 0.0],
            [1.0, 0.0, 0.0],
            [0.0, 1.0, 0.0],
            [0.0, 0.0, 1.0],
        ];
        [[0, 2, 1], [0, 1, 3], [0, 3, 2], [1, 2, 3]]
            .iter()
            .map(|t: &[usize; 3]| stl_io::Triangle {
                normal: stl_io::Normal::new([0.0, 0.0, 0.0]),
                vertices: t.map(|i| stl_io::Vertex::new(p[i])),
            })
            .collect()
    }

    fn binary(triangles: &[stl_io::Triangle]) -> Vec<u8> {
        let mut bytes = Vec::new();
        stl_io::write_stl(&mut bytes, triangles.iter()).expect("writing to memory");
        bytes
    }

    pub(crate) fn ascii(triangles: &[stl_io::Triangle], first_line: &str) -> String {
        let mut s = format!("{first_line}\n");
        for t in triangles {
            s.push_str("  facet normal 0 0 0\n    outer loop\n");
            for v in &t.vertices {
                s.push_str(&format!("      vertex {} {} {}\n", v.0[0], v.0[1], v.0[2]));
            }
            s.push_str("    endloop\n  endfacet\n");
        }
        s.push_str("endsolid\n");
        s
    }

    #[test]
    fn binary_and_ascii_give_the_same_mesh() {
        let from_binary = parse(binary(&tetrahedron())).expect("binary STL");
        assert_eq!(from_binary.vertices.len(), 4, "shared vertices are merged");
        assert_eq!(from_binary.triangles.len(), 4, "four facets");
        assert_eq!(
            from_binary.triangles[0],
            [0, 1, 2],
            "first facet, file order"
        );
        for first_line in ["solid tet", "solid", "  solid\r"] {
            let from_ascii =
                parse(ascii(&tetrahedron(), first_line).into_bytes()).expect("ASCII STL");
            assert_eq!(
                from_ascii, from_binary,
                "ASCII with first line {first_line:?}"
            );
        }
    }

    #[test]
    fn binary_with_a_solid_header_is_read_as_binary() {
        let mut bytes = binary(&tetrahedron());
        bytes[..12].copy_from_slice(b"solid part1 ");
        let mesh = parse(bytes).expect("binary STL whose header starts with solid");
        assert_eq!(mesh.triangles.len(), 4, "all facets read");
    }

    #[test]
    fn truncated_binary_is_malformed() {
        let mut bytes = binary(&tetrahedron());
        bytes.truncate(bytes.len() - 10);
        let err = parse(bytes).expect_err("truncated");
        assert!(
            err.to_string()
                .contains("declares 4 facets (284 bytes) but the file has 274 bytes"),
            "{err}"
        );
        let err = parse(b"hello".to_vec()).expect_err("not STL");
        assert!(err.to_string().contains("too short"), "{err}");
    }

    #[test]
    fn bad_ascii_is_malformed() {
        let text = "solid x\n facet normal 0 0 1\n outer loop\n vertex 1 2\n";
        let err = parse(text.as_bytes().to_vec()).expect_err("bad vertex");
        assert!(matches!(err, StlProblem::Malformed { .. }), "{err}");
    }

    #[test]
    fn empty_and_degenerate_meshes_are_refused() {
        assert!(
            matches!(parse(binary(&[])), Err(StlProblem::NoFacets)),
            "no facets"
        );
        let mut t = tetrahedron();
        for tri in &mut t {
            tri.vertices[2] = tri.vertices[1];
        }
        assert!(
            matches!(parse(binary(&t)), Err(StlProblem::AllDegenerate)),
            "all facets collapsed"
        );
        let mut t = tetrahedron();
        t[1].vertices[1] = t[1].vertices[0];
        let mesh = parse(binary(&t)).expect("one collapsed facet is dropped");
        assert_eq!(
            (mesh.triangles.len(), mesh.dropped_facets),
            (3, 1),
            "dropped facet counted"
        );
    }

    #[test]
    fn non_finite_vertices_are_refused() {
        let mut t = tetrahedron();
        t[2].vertices[1] = stl_io::Vertex::new([f32::NAN, 0.0, 0.0]);
        let err = parse(binary(&t)).expect_err("NaN vertex");
        assert_eq!(
            err.to_string(),
            "facet 2 has a non-finite vertex [NaN, 0, 0]",
            "names the facet"
        );
    }
}
