//! `kerf validate`: load a `kerf.curves/1` file, check it, and summarise it.

use std::io::{self, Write};
use std::path::Path;

use kerf_format::{curves, CurveRecord, CurvesFile, SurfaceGeometry, SurfaceRecord, SurfaceSource};
use serde_json::{json, Value};

use crate::cli::ValidateArgs;
use crate::error::CliError;

/// Runs `kerf validate`.
pub(crate) fn run(args: &ValidateArgs) -> Result<(), CliError> {
    let path = args.curves.as_path();
    let loaded = if path == Path::new("-") {
        curves::from_reader(io::stdin().lock(), Path::new(".")).map_err(|e| e.in_file("<stdin>"))
    } else {
        curves::load(path)
    };
    let stdout = io::stdout();
    let mut out = stdout.lock();
    match loaded {
        Ok(file) => {
            crate::input::warn_unknown_keys(path, &file);
            if args.json {
                let summary = json_summary(path, &file);
                writeln!(out, "{}", pretty(&summary))?;
            } else {
                write_text_summary(&mut out, path, &file)?;
            }
            out.flush()?;
            Ok(())
        }
        Err(error) => {
            if args.json {
                let summary = json!({
                    "file": path.display().to_string(),
                    "valid": false,
                    "error": error.to_string(),
                });
                writeln!(out, "{}", pretty(&summary))?;
                out.flush()?;
            }
            Err(error.into())
        }
    }
}

fn pretty(value: &Value) -> String {
    // Serialising a `Value` cannot fail (its keys are strings); fall back to compact if it did.
    serde_json::to_string_pretty(value).unwrap_or_else(|_| value.to_string())
}

/// What the summary says about one curve.
struct CurveSummary {
    domain: (f64, f64),
    length: f64,
    c0_breaks: Vec<f64>,
    closed: bool,
}

impl CurveSummary {
    fn new(record: &CurveRecord) -> Self {
        let c = &record.curve;
        CurveSummary {
            domain: c.domain(),
            length: c.arc_length(),
            c0_breaks: c.c0_breaks(),
            closed: c.is_closed(),
        }
    }
}

fn json_summary(path: &Path, file: &CurvesFile) -> Value {
    let curves: Vec<Value> = file
        .curves
        .iter()
        .map(|r| {
            let s = CurveSummary::new(r);
            json!({
                "id": r.id,
                "degree": r.curve.degree(),
                "control_points": r.curve.len(),
                "rational": r.curve.is_rational(),
                "domain": [s.domain.0, s.domain.1],
                "length": s.length,
                "c0_breaks": s.c0_breaks,
                "closed": s.closed,
                "surface": r.surface,
            })
        })
        .collect();
    let surfaces: Vec<Value> = file.surfaces.iter().map(surface_json).collect();
    json!({
        "file": path.display().to_string(),
        "valid": true,
        "format": kerf_format::CURVES_FORMAT,
        "units": file.units.name(),
        "curves": curves,
        "surfaces": surfaces,
        "warnings": file.warnings.iter().map(ToString::to_string).collect::<Vec<_>>(),
    })
}

fn surface_json(s: &SurfaceRecord) -> Value {
    let mut v = json!({ "id": s.id, "type": s.type_name() });
    match &s.geometry {
        SurfaceGeometry::Nurbs(n) => {
            let (rows, cols) = n.net_size();
            v["degree_u"] = json!(n.degree_u());
            v["degree_v"] = json!(n.degree_v());
            v["control_points"] = json!([rows, cols]);
            v["rational"] = json!(n.is_rational());
        }
        SurfaceGeometry::Mesh {
            vertices,
            triangles,
        } => {
            v["vertices"] = json!(vertices.len());
            v["triangles"] = json!(triangles.len());
        }
    }
    if let SurfaceSource::Stl {
        path,
        dropped_facets,
    } = &s.source
    {
        v["path"] = json!(path.display().to_string());
        v["dropped_facets"] = json!(dropped_facets);
    }
    v
}

/// `1 curve`, `2 curves`; `plural` is the word's plural form.
fn count(n: usize, singular: &str, plural: &str) -> String {
    format!("{n} {}", if n == 1 { singular } else { plural })
}

fn yes_no(b: bool) -> String {
    if b { "yes" } else { "no" }.to_owned()
}

fn write_text_summary(out: &mut impl Write, path: &Path, file: &CurvesFile) -> io::Result<()> {
    writeln!(
        out,
        "{}: valid {}, units {}, {}, {}",
        path.display(),
        kerf_format::CURVES_FORMAT,
        file.units,
        count(file.curves.len(), "curve", "curves"),
        count(file.surfaces.len(), "surface", "surfaces"),
    )?;
    if !file.curves.is_empty() {
        let mut rows = vec![[
            "id",
            "degree",
            "points",
            "rational",
            "domain",
            "length/mm",
            "C0 breaks",
            "closed",
            "surface",
        ]
        .map(str::to_owned)];
        for r in &file.curves {
            let s = CurveSummary::new(r);
            rows.push([
                r.id.clone(),
                r.curve.degree().to_string(),
                r.curve.len().to_string(),
                yes_no(r.curve.is_rational()),
                format!(
                    "[{}, {}]",
                    kerf_nurbs::Readable(s.domain.0),
                    kerf_nurbs::Readable(s.domain.1)
                ),
                format!("{:.3}", s.length),
                s.c0_breaks.len().to_string(),
                yes_no(s.closed),
                r.surface.clone().unwrap_or_else(|| "-".to_owned()),
            ]);
        }
        writeln!(out, "\ncurves:")?;
        write_table(out, &rows)?;
    }
    if !file.surfaces.is_empty() {
        let mut rows = vec![["id", "type", "size"].map(str::to_owned)];
        for s in &file.surfaces {
            let size = match &s.geometry {
                SurfaceGeometry::Nurbs(n) => {
                    let (rows, cols) = n.net_size();
                    format!(
                        "degree {} x {}, {rows} x {cols} control points, {}",
                        n.degree_u(),
                        n.degree_v(),
                        if n.is_rational() {
                            "rational"
                        } else {
                            "polynomial"
                        }
                    )
                }
                SurfaceGeometry::Mesh {
                    vertices,
                    triangles,
                } => format!(
                    "{}, {}",
                    count(vertices.len(), "vertex", "vertices"),
                    count(triangles.len(), "triangle", "triangles")
                ),
            };
            let size = match &s.source {
                SurfaceSource::Inline => size,
                SurfaceSource::Stl {
                    path,
                    dropped_facets: 0,
                } => format!("{size}, from {}", path.display()),
                SurfaceSource::Stl {
                    path,
                    dropped_facets,
                } => format!(
                    "{size}, from {} ({} with coinciding corners dropped)",
                    path.display(),
                    count(*dropped_facets, "facet", "facets")
                ),
            };
            rows.push([s.id.clone(), s.type_name().to_owned(), size]);
        }
        writeln!(out, "\nsurfaces:")?;
        write_table(out, &rows)?;
    }
    Ok(())
}

/// Writes rows as left-aligned columns, indented by two spaces.
fn write_table<const N: usize>(out: &mut impl Write, rows: &[[String; N]]) -> io::Result<()> {
    let mut widths = [0; N];
    for row in rows {
        for (w, cell) in widths.iter_mut().zip(row) {
            *w = (*w).max(cell.chars().count());
        }
    }
    for row in rows {
        let mut line = String::from(" ");
        for (k, (cell, w)) in row.iter().zip(widths).enumerate() {
            line.push(' ');
            line.push_str(cell);
            if k + 1 < N {
                line.push_str(&" ".repeat(w - cell.chars().count() + 1));
            }
        }
        writeln!(out, "{}", line.trim_end())?;
    }
    Ok(())
}
