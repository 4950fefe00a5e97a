//! Triangle meshes as normal sources, through parry3d's `TriMesh`.
//!
//! The normal inside a triangle is interpolated (barycentric) from its three *corner normals*.
//! A corner normal at vertex `v` of face `f` is the angle-weighted average of the normals of
//! the faces around `v` whose normal is within the crease angle of `f`'s (Thuermer and
//! Wuethrich's angle weighting). So the normal varies continuously across smooth regions,
//! while a real edge (faces meeting at more than the crease angle) splits the vertex normal
//! and is never rounded off.

use nalgebra::{Point3, Vector3};
use parry3d_f64::query::PointQueryWithLocation;
use parry3d_f64::shape::{TriMesh, TriMeshFlags};

use crate::error::{NormalsError, Result};
use crate::surface::{Hint, NormalSource, Projection};

/// A triangle mesh with crease-aware smooth normals.
#[derive(Debug, Clone)]
pub struct MeshNormals {
    mesh: TriMesh,
    /// `corner[3 f + k]`: the normal at corner `k` of triangle `f`.
    corner: Vec<Vector3<f64>>,
    flip: bool,
}

/// The default crease angle: faces meeting at more than this are an edge, not a curved
/// surface.
pub const DEFAULT_CREASE_ANGLE_DEG: f64 = 30.0;

/// The largest vertex coordinate a mesh may have, mm (1,000 km). The distance queries square
/// coordinate differences and the face normals square cross products (fourth powers of the
/// coordinates): far beyond any part, yet small enough that neither overflows (a vertex at
/// 1e155 mm made parry's query panic, one at 1e100 mm lost every face normal).
pub const MAX_MESH_COORDINATE_MM: f64 = 1e9;

impl MeshNormals {
    /// Builds the mesh (duplicate vertices merged, degenerate triangles removed) and its corner
    /// normals. The normal follows the winding (counter-clockwise = outward), reversed if
    /// `flip`. `crease_angle_deg` in degrees (like [`DEFAULT_CREASE_ANGLE_DEG`]).
    ///
    /// # Errors
    /// [`NormalsError::BadMesh`] for non-finite vertices or ones beyond
    /// [`MAX_MESH_COORDINATE_MM`], bad indices or no usable triangle;
    /// [`NormalsError::BadOption`] for a crease angle outside `[0, 180]` degrees.
    pub fn new(
        vertices: Vec<Point3<f64>>,
        triangles: Vec<[u32; 3]>,
        crease_angle_deg: f64,
        flip: bool,
    ) -> Result<Self> {
        if !(0.0..=180.0).contains(&crease_angle_deg) {
            return Err(NormalsError::BadOption {
                name: "crease_angle_deg",
                value: crease_angle_deg,
                reason: "must lie in [0, 180] degrees",
            });
        }
        if let Some(i) = vertices
            .iter()
            .position(|v| !v.coords.iter().all(|x| x.is_finite()))
        {
            return Err(NormalsError::BadMesh(format!("vertex {i} is not finite")));
        }
        if let Some((i, v)) = vertices
            .iter()
            .enumerate()
            .find(|(_, v)| v.coords.amax() > MAX_MESH_COORDINATE_MM)
        {
            return Err(NormalsError::BadMesh(format!(
                "vertex {i} has a coordinate of {:e} mm, beyond the {MAX_MESH_COORDINATE_MM:e} mm a mesh may reach",
                v.coords.amax()
            )));
        }
        let n = vertices.len() as u32;
        if let Some(t) = triangles.iter().position(|t| t.iter().any(|&i| i >= n)) {
            return Err(NormalsError::BadMesh(format!(
                "triangle {t} has a vertex index >= {n}"
            )));
        }
        let flags =
            TriMeshFlags::MERGE_DUPLICATE_VERTICES | TriMeshFlags::DELETE_DEGENERATE_TRIANGLES;
        let mesh = TriMesh::with_flags(vertices, triangles, flags)
            .map_err(|e| NormalsError::BadMesh(format!("{e:?}")))?;
        let corner = corner_normals(
            mesh.vertices(),
            mesh.indices(),
            crease_angle_deg.to_radians(),
        );
        if corner.iter().all(|c| c.norm() == 0.0) {
            return Err(NormalsError::BadMesh(
                "no triangle with a non-zero area".into(),
            ));
        }
        Ok(Self { mesh, corner, flip })
    }

    /// Number of triangles after cleaning.
    pub fn triangle_count(&self) -> usize {
        self.mesh.indices().len()
    }

    /// The interpolated unit normal at barycentric coordinates `bary` of triangle `tri`.
    pub fn normal_at(&self, tri: u32, bary: [f64; 3]) -> Option<Vector3<f64>> {
        let base = 3 * tri as usize;
        let n = self.corner[base] * bary[0]
            + self.corner[base + 1] * bary[1]
            + self.corner[base + 2] * bary[2];
        let len = n.norm();
        (len > 1e-12).then(|| if self.flip { -n / len } else { n / len })
    }
}

impl NormalSource for MeshNormals {
    fn project(&self, p: &Point3<f64>, _hint: Hint) -> Projection {
        let (proj, (tri, _)) = self.mesh.project_local_point_and_get_location(p, false);
        // Barycentric coordinates computed here from the projected point: parry's conversion
        // of its edge locations uses another edge numbering than its triangles (noted in its
        // source), which would interpolate between the wrong corners on an edge.
        let [a, b, c] = self.mesh.indices()[tri as usize].map(|i| self.mesh.vertices()[i as usize]);
        let bary = barycentric(&proj.point, &a, &b, &c);
        Projection {
            point: proj.point,
            distance: (proj.point - p).norm(),
            normal: self.normal_at(tri, bary),
            hint: Hint::Triangle(tri),
        }
    }
}

/// Corner normals: for corner `k` of face `f` at vertex `v`, the angle-weighted sum of the unit
/// normals of the faces around `v` within `crease` of `f`'s normal, normalised.
fn corner_normals(vertices: &[Point3<f64>], tris: &[[u32; 3]], crease: f64) -> Vec<Vector3<f64>> {
    let face: Vec<(Vector3<f64>, [f64; 3])> = tris
        .iter()
        .map(|t| {
            let [a, b, c] = t.map(|i| vertices[i as usize]);
            let n = (b - a).cross(&(c - a));
            let unit = if n.norm() > 0.0 {
                n.normalize()
            } else {
                Vector3::zeros()
            };
            let angle = |p: Point3<f64>, q: Point3<f64>, r: Point3<f64>| (q - p).angle(&(r - p));
            (unit, [angle(a, b, c), angle(b, c, a), angle(c, a, b)])
        })
        .collect();
    let mut around: Vec<Vec<(usize, usize)>> = vec![Vec::new(); vertices.len()];
    for (f, t) in tris.iter().enumerate() {
        for (k, &v) in t.iter().enumerate() {
            around[v as usize].push((f, k));
        }
    }
    let cos_crease = crease.cos();
    let mut corner = vec![Vector3::zeros(); 3 * tris.len()];
    for (f, t) in tris.iter().enumerate() {
        let nf = face[f].0;
        for (k, &v) in t.iter().enumerate() {
            let mut sum = Vector3::zeros();
            for &(g, kg) in &around[v as usize] {
                let ng = face[g].0;
                if g == f || ng.dot(&nf) >= cos_crease - 1e-12 {
                    sum += ng * face[g].1[kg];
                }
            }
            corner[3 * f + k] = if sum.norm() > 0.0 {
                sum.normalize()
            } else {
                nf
            };
        }
    }
    corner
}

/// Barycentric coordinates of `q` (on or near the plane of the triangle) with respect to
/// `a, b, c`, clamped to the triangle.
fn barycentric(q: &Point3<f64>, a: &Point3<f64>, b: &Point3<f64>, c: &Point3<f64>) -> [f64; 3] {
    let (v0, v1, v2) = (b - a, c - a, q - a);
    let (d00, d01, d11) = (v0.dot(&v0), v0.dot(&v1), v1.dot(&v1));
    let (d20, d21) = (v2.dot(&v0), v2.dot(&v1));
    let den = d00 * d11 - d01 * d01;
    if den <= 0.0 {
        return [1.0 / 3.0; 3];
    }
    let v = ((d11 * d20 - d01 * d21) / den).clamp(0.0, 1.0);
    let w = ((d00 * d21 - d01 * d20) / den).clamp(0.0, 1.0 - v);
    [1.0 - v - w, v, w]
}
