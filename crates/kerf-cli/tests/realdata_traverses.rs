//! The traverses of the real files (`kerf run --place auto` on the gantry): how many are
//! checked against the part, and the residue with its reasons asserted exactly, so that a
//! change that loses a route (or finds one) shows here. Every gap is either written as a
//! checked traverse into `axes.json` or listed as unchecked with the reason; every listed
//! own-surface exemption names a surface the neighbouring cut's curve names. The distances
//! the report names (the proof of a blocked approach line) and the machine's rapid moves of
//! the searched traverses are measured again here, independently: the global closest point of
//! each NURBS surface of the set-up (not the tessellation-started one the checks use), the
//! machine's moves through its forward kinematics.

mod common;

use common::{fixture, read_json, run_auto_with};
use kerf_kinematics::{Axes, Machine, Placement};
use kerf_nurbs::NurbsSurface;
use nalgebra::{Point3, Vector3};
use serde_json::Value;

/// The run of a real file placed automatically on the gantry, the head check off (the bend
/// and blade edges meet the head; its traverse figures are in docs/process.md).
fn run(curves: &str, more: &[&str]) -> (Value, Value, Value) {
    let mut args = vec!["--cut-clearance", "off"];
    args.extend_from_slice(more);
    let dir = run_auto_with(curves, "gantry_ac.json", &args);
    let curves_file = read_json(&fixture(curves));
    (
        read_json(&dir.path().join("report.json")),
        read_json(&dir.path().join("axes.json")),
        curves_file,
    )
}

/// The surfaces of the set-up that holds the cut `id`, without `left_out`, placed as the report
/// says (control points moved by the placement: exact for a rigid motion).
fn setup_surfaces(
    file: &kerf_format::CurvesFile,
    report: &Value,
    id: &str,
    left_out: &[String],
) -> Vec<NurbsSurface> {
    let setups = report["placement"]["setups"].as_array().expect("setups");
    let setup = setups
        .iter()
        .find(|s| s["paths"].as_array().unwrap().iter().any(|p| p == id))
        .expect("the cut's set-up");
    let numbers = |v: &Value| -> Vec<f64> {
        v.as_array()
            .expect("numbers")
            .iter()
            .map(|x| x.as_f64().expect("number"))
            .collect()
    };
    let (t, r) = (
        numbers(&setup["translation_mm"]),
        numbers(&setup["rotation_deg"]),
    );
    let placement = Placement::new(Vector3::new(t[0], t[1], t[2]), [r[0], r[1], r[2]]);
    let mut ids: Vec<&str> = Vec::new();
    for p in setup["paths"].as_array().unwrap() {
        let c = file
            .curves
            .iter()
            .find(|c| c.id == p.as_str().unwrap())
            .expect("curve");
        for s in &c.surfaces {
            if !ids.contains(&s.as_str()) && !left_out.contains(s) {
                ids.push(s);
            }
        }
    }
    ids.iter()
        .filter_map(|id| match &file.surface(id)?.geometry {
            kerf_format::SurfaceGeometry::Nurbs(n) => {
                let cps = n
                    .control_points()
                    .iter()
                    .map(|row| row.iter().map(|p| placement.apply_point(p)).collect())
                    .collect();
                Some(
                    NurbsSurface::try_new(
                        n.degree_u(),
                        n.degree_v(),
                        n.knots_u().to_vec(),
                        n.knots_v().to_vec(),
                        cps,
                        n.is_rational().then(|| n.weights()),
                    )
                    .expect("placed surface"),
                )
            }
            kerf_format::SurfaceGeometry::Mesh { .. } => panic!("the real files hold NURBS"),
        })
        .collect()
}

/// The distance from `p` to the nearest of `surfaces` (the global closest point of each whose
/// control-point box, which contains it, is nearer than `limit`), or `limit` if none is.
fn distance(surfaces: &[NurbsSurface], p: &Point3<f64>, limit: f64) -> f64 {
    surfaces
        .iter()
        .filter(|s| {
            let (lo, hi) = s.bounding_box();
            let d = Vector3::from_fn(|k, _| (lo[k] - p[k]).max(p[k] - hi[k]).max(0.0));
            d.norm() < limit
        })
        .map(|s| s.closest_point(p, None).distance)
        .fold(limit, f64::min)
}

fn strings(v: &Value) -> Vec<String> {
    v.as_array()
        .map(|a| a.iter().map(|s| s.as_str().unwrap().to_string()).collect())
        .unwrap_or_default()
}

#[test]
fn real_files_route_every_traverse_but_an_asserted_residue() {
    // (file, extra arguments, gaps, unchecked, searched, walls, own, turned, both):
    // `searched` gaps are those where no route shape (straight, lifted over the nearby
    // surfaces, over the safe plane, each at two heights and with five retract heights at each
    // end) clears and the search around the part found a path (the head turned upright for
    // the travel); the `unchecked` residue is proven impossible: the approach line to the
    // pierce is blocked at every height (the reason says 'proven'). `walls`: contours cut
    // with the beam along their thin wall (hole walls up to 4 mm, `--max-wall`; `0` turns
    // that off, and the sheet-metal file then keeps the walls' radial normals as tool axes,
    // the case the proof and the search were made on). `own` gaps leave out a cut's own
    // surface that curls over its head line (with the rule: holes cut from the other face of
    // the sheet for reach, whose modelled nozzle runs through the hole from the focus on the
    // far rim; bends; walls thicker than 4 mm; without it: holes narrower than the clearance
    // cut with the wall's radial normal). `turned`: contours cut from the other side because
    // the nozzle's line meets the part from the given side and not from the other; `both`:
    // contours kept although their nozzle's line meets the part from both sides (or the
    // head cannot reach the clear side).
    let machine = Machine::read(fixture("machines").join("gantry_ac.json")).expect("machine");
    for (curves, more, gaps, unchecked, searched, walls, own, turned, both) in [
        (
            "realdata/nori_sheetmetal.json",
            &[][..],
            75,
            0,
            0,
            35,
            10,
            0,
            3,
        ),
        (
            "realdata/nori_sheetmetal.json",
            &["--max-wall", "0"][..],
            74,
            1,
            1,
            0,
            9,
            6,
            13,
        ),
        (
            "realdata/occt_propeller.json",
            &[][..],
            46,
            0,
            3,
            0,
            1,
            9,
            13,
        ),
    ] {
        let (report, axes, file) = run(curves, more);
        assert_eq!(
            report["placement"]["walls"]
                .as_array()
                .expect("walls")
                .len(),
            walls,
            "{curves} {more:?}"
        );
        let parsed = kerf_format::curves::load(fixture(curves)).expect("curves");
        let sides = report["placement"]["sides"].as_array().expect("sides");
        let reasons = |needle: &str| {
            sides
                .iter()
                .filter(|s| s["reason"].as_str().expect("reason").contains(needle))
                .collect::<Vec<_>>()
        };
        let by_head = reasons("from the other side at none");
        assert_eq!(by_head.len(), turned, "{curves}: {sides:#?}");
        let flipped = report["placement"]["flipped_paths"]
            .as_array()
            .expect("flipped");
        for s in &by_head {
            assert_eq!(s["side"], "other", "{s}");
            assert!(flipped.contains(&s["id"]), "{curves}: {s}");
        }
        let kept = reasons("both sides").len() + reasons("cannot reach the other side").len();
        assert_eq!(kept, both, "{curves}: {sides:#?}");
        let t = &report["traverses"];
        let clearance = t["clearance_mm"].as_f64().expect("clearance");
        assert_eq!(t["count"].as_u64(), Some(gaps), "{curves}: gaps");
        let listed = t["unchecked"].as_array().expect("unchecked");
        assert_eq!(listed.len(), unchecked, "{curves}: unchecked {listed:#?}");
        for u in listed {
            let why = u["reason"].as_str().expect("reason");
            assert!(
                why.contains("(proven, no route can exist: the approach to the pierce along the tool axis is blocked at every retract height"),
                "{curves}: {why}"
            );
            // The named sample is closer than half the clearance (it blocks every approach
            // reaching it), measured again independently against the surfaces checked.
            let tail = why.rsplit("; (").next().expect("the sample");
            let xyz: Vec<f64> = tail
                .split(')')
                .next()
                .unwrap()
                .split(", ")
                .map(|v| v.parse().expect("coordinate"))
                .collect();
            let d: f64 = tail
                .rsplit(") is ")
                .next()
                .and_then(|t| t.split(" mm").next())
                .and_then(|t| t.parse().ok())
                .expect("the distance in the reason");
            assert!(d < 0.5 * clearance, "{curves}: {why}");
            let left_out = strings(&u["surfaces_left_out"]);
            let surfaces =
                setup_surfaces(&parsed, &report, u["before"].as_str().unwrap(), &left_out);
            let exact = distance(&surfaces, &Point3::new(xyz[0], xyz[1], xyz[2]), 1e3);
            assert!(
                (exact - d).abs() < 2e-3,
                "{curves}: the sample is {exact} mm from the part, the reason says {d}"
            );
        }
        // The searched traverses: the machine's rapid moves as it runs them (all axes linear
        // between the written positions), sampled every 2 mm of tip travel with the nozzle
        // every 2 mm, every sample at least the clearance from the surfaces checked.
        let found = t["searched"].as_array().expect("searched");
        assert_eq!(found.len(), searched, "{curves}: searched {found:#?}");
        assert_eq!(t["routes"]["searched"].as_u64(), Some(searched as u64));
        let paths = axes["paths"].as_array().expect("paths");
        for s in found {
            let before = s["before"].as_str().unwrap();
            let left_out = strings(&s["surfaces_left_out"]);
            let surfaces = setup_surfaces(&parsed, &report, before, &left_out);
            let p = paths.iter().find(|p| p["id"] == before).expect("path");
            let positions: Vec<[f64; 5]> = p["traverse"]["positions"]
                .as_array()
                .expect("the traverse's positions")
                .iter()
                .map(|r| std::array::from_fn(|k| r[k].as_f64().unwrap()))
                .collect();
            let nozzle = t["nozzle_mm"].as_f64().unwrap();
            let mut least = f64::INFINITY;
            for w in positions.windows(2) {
                let at = |f: f64| {
                    let v: [f64; 5] = std::array::from_fn(|k| w[0][k] + (w[1][k] - w[0][k]) * f);
                    machine
                        .kinematics
                        .forward(&Axes::new(v[0], v[1], v[2], v[3], v[4]))
                };
                let (a, b) = (at(0.0), at(1.0));
                let k = (((b.position - a.position).norm() / 2.0).ceil() as usize).max(8);
                for j in 0..=k {
                    let pose = at(j as f64 / k as f64);
                    for s in 0..=10 {
                        let q = pose.position + pose.axis * (nozzle * s as f64 / 10.0);
                        least = least.min(distance(&surfaces, &q, clearance + 1.0));
                    }
                }
            }
            assert!(
                least >= clearance,
                "{curves}: the searched traverse before {before} comes {least} mm from the part"
            );
        }
        assert_eq!(
            t["checked_count"].as_u64(),
            Some(gaps - unchecked as u64),
            "{curves}"
        );
        assert!(
            t["min_distance_mm"].as_f64().expect("min") >= clearance,
            "{curves}: a checked traverse closer than the clearance"
        );
        // Every gap of a set-up: a checked traverse in axes.json, or listed as unchecked.
        let written = paths.iter().filter(|p| p.get("traverse").is_some()).count();
        assert_eq!(written as u64, gaps - unchecked as u64, "{curves}: written");
        for u in listed {
            let before = u["before"].as_str().expect("before");
            let p = paths
                .iter()
                .find(|p| p["id"] == before)
                .expect("the listed cut");
            assert!(p.get("traverse").is_none(), "{curves}: {before}");
        }
        // Own-surface exemptions name a surface of one of the two cuts.
        let surfaces_of = |id: &str| -> Vec<String> {
            let c = file["curves"]
                .as_array()
                .expect("curves")
                .iter()
                .find(|c| c["id"] == id)
                .expect("curve");
            let mut s: Vec<String> = c["surfaces"]
                .as_array()
                .map(|a| a.iter().map(|v| v.as_str().unwrap().to_string()).collect())
                .unwrap_or_default();
            if let Some(one) = c["surface"].as_str() {
                s.push(one.to_string());
            }
            s
        };
        let owns = t["own_surface_over_the_head"].as_array().expect("own");
        assert_eq!(owns.len(), own, "{curves}: {owns:#?}");
        for o in owns {
            let mut named = surfaces_of(o["after"].as_str().unwrap());
            named.extend(surfaces_of(o["before"].as_str().unwrap()));
            for s in o["surfaces"].as_array().unwrap() {
                assert!(named.contains(&s.as_str().unwrap().to_string()), "{o}");
            }
        }
    }
}
