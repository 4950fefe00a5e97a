//! What a picture shows, as plain data: sampled curves, cutting points, normals, chord errors
//! and machine axes. Built from kerf's files by [`Scene::new`] and [`AxesChart::new`], or by
//! hand for data from elsewhere.

use kerf_format::{CurvesFile, ToolpathFile};
use kerf_kinematics::{AxesFile, Machine};
use kerf_nurbs::{NurbsCurve, Segment};
use nalgebra::{Point3, Vector3};

use crate::PlotError;

/// Everything one picture shows.
#[derive(Debug, Clone, PartialEq)]
pub struct Scene {
    /// The title at the top of the picture.
    pub title: String,
    /// A line under the title (files, tolerance, counts).
    pub subtitle: String,
    /// The chord tolerance, in mm (> 0; the colour scale and the tolerance line use it).
    pub tolerance: f64,
    /// The paths, in toolpath order.
    pub paths: Vec<PathPicture>,
    /// The machine axes, if known.
    pub axes: Option<AxesChart>,
    /// The laser process over the paths (pierces, lead-ins and lead-outs, cutting order,
    /// traverses), if planned.
    pub process: Option<ProcessPicture>,
}

/// The laser process drawn over the paths, in the same coordinates as the paths: each cut's
/// pierce as a marker numbered in cutting order, its lead-in and lead-out in their own
/// styles, and the traverses between cuts dashed.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct ProcessPicture {
    /// The cuts in cutting order (the number drawn by a pierce is its index here plus one).
    pub cuts: Vec<CutPicture>,
    /// The traverses: the tip's polyline from one cut's exit to the next cut's pierce.
    pub traverses: Vec<Vec<Point3<f64>>>,
}

/// One cut of [`ProcessPicture`].
#[derive(Debug, Clone, PartialEq)]
pub struct CutPicture {
    /// The contour's id.
    pub id: String,
    /// Where the beam pierces (the lead-in's first point, or the contour's start when the
    /// cut pierces on the contour).
    pub pierce: Point3<f64>,
    /// The lead-in from the pierce to the contour (empty: none).
    pub lead_in: Vec<Point3<f64>>,
    /// The lead-out from the contour's last cutting point (empty: none).
    pub lead_out: Vec<Point3<f64>>,
    /// The micro-joints on the contour: where the beam goes off and on again (empty: none).
    pub micro_joints: Vec<[Point3<f64>; 2]>,
    /// Stretches of the cut whose tool axis was tilted to clear the head (`kerf run`'s head
    /// check with a tilt tolerance; empty: none).
    pub head_tilted: Vec<Vec<Point3<f64>>>,
    /// Stretches where the head comes closer to the part than the cutting clearance (accepted
    /// as warnings; empty: none).
    pub head_close: Vec<Vec<Point3<f64>>>,
}

/// One cut contour: its curve, cutting points, normals and per-segment chord errors.
#[derive(Debug, Clone, PartialEq)]
pub struct PathPicture {
    /// The path's id.
    pub id: String,
    /// The curve, densely sampled.
    pub curve: Vec<Point3<f64>>,
    /// The cutting points.
    pub points: Vec<Point3<f64>>,
    /// The unit normals (tool axes) of the points, if the toolpath has them.
    pub normals: Option<Vec<Vector3<f64>>>,
    /// The chord error of each segment (`points.len() - 1` values), in mm.
    pub segment_errors: Vec<f64>,
}

/// Machine axis positions over the points, with the machine's limits.
#[derive(Debug, Clone, PartialEq)]
pub struct AxesChart {
    /// The machine's name.
    pub machine: String,
    /// The axis names, `X, Y, Z, A|B, C`.
    pub names: [String; 5],
    /// The positions of each path, `[X, Y, Z, tilt, C]` (mm, degrees).
    pub paths: Vec<(String, Vec<[f64; 5]>)>,
    /// `[min, max]` per axis; `None` for a continuous axis or unknown limits.
    pub limits: [Option<(f64, f64)>; 5],
    /// True if the limits come from a machine file (else none are drawn).
    pub limits_known: bool,
}

/// How densely to sample.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[non_exhaustive]
pub struct SceneOptions {
    /// Samples per segment for the displayed chord error (default 32).
    pub error_samples: usize,
    /// Samples of a curve as long as the whole scene is wide, for drawing it (default 2000);
    /// shorter curves get proportionally fewer, but at least 64 and 16 per knot span, and
    /// none more than this.
    pub curve_samples: usize,
}

impl Default for SceneOptions {
    fn default() -> Self {
        Self {
            error_samples: 32,
            curve_samples: 2000,
        }
    }
}

impl SceneOptions {
    /// Sets [`error_samples`](Self::error_samples): samples per segment for the displayed
    /// chord error (default 32).
    pub fn with_error_samples(mut self, error_samples: usize) -> Self {
        self.error_samples = error_samples;
        self
    }

    /// Sets [`curve_samples`](Self::curve_samples): samples of a curve as long as the whole
    /// scene is wide, for drawing it (default 2000).
    pub fn with_curve_samples(mut self, curve_samples: usize) -> Self {
        self.curve_samples = curve_samples;
        self
    }
}

impl Scene {
    /// The scene of `toolpath` on `curves`: each path is drawn with the curve of the same id.
    ///
    /// The chord error of each segment is a sampled estimate (`opts.error_samples` equal
    /// parameter steps; for display, not a proof: `kerf check` measures it properly).
    ///
    /// # Errors
    /// [`PlotError::UnknownCurve`] if a path's id names no curve.
    pub fn new(
        curves: &CurvesFile,
        toolpath: &ToolpathFile,
        opts: &SceneOptions,
    ) -> Result<Scene, PlotError> {
        // The size of the scene: the diagonal of the curves' control-point boxes.
        let mut lo = Vector3::repeat(f64::INFINITY);
        let mut hi = Vector3::repeat(f64::NEG_INFINITY);
        for c in &curves.curves {
            let (a, b) = c.curve.bounding_box();
            lo = lo.inf(&a.coords);
            hi = hi.sup(&b.coords);
        }
        let extent = (hi - lo).norm();
        let mut paths = Vec::with_capacity(toolpath.paths.len());
        for (index, p) in toolpath.paths.iter().enumerate() {
            let curve = curves
                .curves
                .iter()
                .find(|c| c.id == p.id)
                .map(|c| &c.curve)
                .ok_or_else(|| PlotError::UnknownCurve {
                    index,
                    id: p.id.clone(),
                })?;
            let points: Vec<Point3<f64>> =
                (0..p.points.len()).map(|n| p.points.position(n)).collect();
            let normals = p.points.has_normals().then(|| {
                (0..p.points.len())
                    .filter_map(|n| p.points.normal(n))
                    .collect()
            });
            let segment_errors = p
                .params
                .windows(2)
                .zip(points.windows(2))
                .map(|(t, q)| {
                    sampled_chord_error(curve, t[0], t[1], &q[0], &q[1], opts.error_samples)
                })
                .collect();
            paths.push(PathPicture {
                id: p.id.clone(),
                curve: {
                    let share = curve.arc_length() / extent;
                    let n = if share.is_finite() {
                        (share * opts.curve_samples as f64).ceil() as usize
                    } else {
                        opts.curve_samples
                    };
                    sample_curve(
                        curve,
                        n.clamp(64.min(opts.curve_samples), opts.curve_samples),
                    )
                },
                points,
                normals,
                segment_errors,
            });
        }
        let points: usize = paths.iter().map(|p| p.points.len()).sum();
        Ok(Scene {
            title: "kerf toolpath".into(),
            subtitle: format!(
                "{} paths, {points} cutting points, tolerance {} mm",
                paths.len(),
                toolpath.tolerance
            ),
            tolerance: toolpath.tolerance,
            paths,
            axes: None,
            process: None,
        })
    }
}

impl AxesChart {
    /// The axes of `axes`, with the limits of `machine` if given.
    ///
    /// # Errors
    /// [`PlotError::MachineMismatch`] if the machine's name or tilt axis differs from the one
    /// the axes file was computed for.
    pub fn new(axes: &AxesFile, machine: Option<&Machine>) -> Result<AxesChart, PlotError> {
        let mut limits = [None; 5];
        if let Some(m) = machine {
            let names = m.axis_names();
            if m.name != axes.machine || names[3] != axes.axes[3] {
                return Err(PlotError::MachineMismatch {
                    axes: format!("{} (tilt {})", axes.machine, axes.axes[3]),
                    machine: format!("{} (tilt {})", m.name, names[3]),
                });
            }
            for (l, r) in limits.iter_mut().zip(&m.limits) {
                *l = r.map(|r| (r.min, r.max));
            }
        }
        Ok(AxesChart {
            machine: axes.machine.clone(),
            names: axes.axes.clone(),
            paths: axes
                .paths
                .iter()
                .map(|p| (p.id.clone(), p.positions.clone()))
                .collect(),
            limits,
            limits_known: machine.is_some(),
        })
    }
}

/// `n` points of `curve` spread over its knot spans (at least 16 per span), in order.
pub fn sample_curve(curve: &NurbsCurve, n: usize) -> Vec<Point3<f64>> {
    let spans = curve.spans();
    if spans.is_empty() {
        let (a, b) = curve.domain();
        return vec![curve.point(a), curve.point(b)];
    }
    let per = (n / spans.len()).max(16);
    let mut out = Vec::with_capacity(per * spans.len() + 1);
    out.push(curve.point(spans[0].1));
    for &(_, a, b) in &spans {
        for k in 1..=per {
            out.push(curve.point(a + (b - a) * (k as f64 / per as f64)));
        }
    }
    out
}

/// The largest distance from `samples` equally spaced points of the curve on `[t0, t1]` to
/// the chord `p0 p1`: an estimate from below of the chord error, for display.
pub fn sampled_chord_error(
    curve: &NurbsCurve,
    t0: f64,
    t1: f64,
    p0: &Point3<f64>,
    p1: &Point3<f64>,
    samples: usize,
) -> f64 {
    let n = samples.max(2);
    let chord = Segment::between(p0, p1);
    (0..=n)
        .map(|k| chord.distance_to(&curve.point(t0 + (t1 - t0) * (k as f64 / n as f64))))
        .fold(0.0, f64::max)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn arc() -> NurbsCurve {
        let h = std::f64::consts::FRAC_1_SQRT_2;
        NurbsCurve::try_new(
            2,
            vec![0.0, 0.0, 0.0, 1.0, 1.0, 1.0],
            vec![
                Point3::new(10.0, 0.0, 0.0),
                Point3::new(10.0, 10.0, 0.0),
                Point3::new(0.0, 10.0, 0.0),
            ],
            Some(vec![1.0, h, 1.0]),
        )
        .unwrap()
    }

    #[test]
    fn samples_lie_on_the_curve_in_order() {
        let c = arc();
        let s = sample_curve(&c, 100);
        assert_eq!(s.len(), 101, "one span, 100 steps");
        assert!(
            s.iter().all(|p| (p.coords.norm() - 10.0).abs() < 1e-12),
            "on the circle"
        );
        assert_eq!(s[0], c.point(0.0), "from the start");
        assert_eq!(*s.last().unwrap(), c.point(1.0), "to the end");
    }

    #[test]
    fn the_sampled_error_of_a_quarter_circle_is_its_sagitta() {
        let c = arc();
        let e = sampled_chord_error(&c, 0.0, 1.0, &c.point(0.0), &c.point(1.0), 32);
        let sagitta = 10.0 * (1.0 - std::f64::consts::FRAC_PI_4.cos());
        assert!(
            e <= sagitta + 1e-12 && e > 0.99 * sagitta,
            "{e} vs {sagitta}"
        );
    }

    fn fixture(name: &str) -> std::path::PathBuf {
        std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
            .join("../../fixtures")
            .join(name)
    }

    /// 21 equally spaced params per curve, points on the curve.
    fn toolpath(file: &CurvesFile) -> ToolpathFile {
        use kerf_format::{ToolpathPoints, ToolpathRecord};
        ToolpathFile {
            units: kerf_format::Units::Millimetres,
            tolerance: 0.5,
            paths: file
                .curves
                .iter()
                .map(|c| {
                    let (a, b) = c.curve.domain();
                    let params: Vec<f64> = (0..=20)
                        .map(|k| a + (b - a) * f64::from(k) / 20.0)
                        .collect();
                    let points = params
                        .iter()
                        .map(|&t| c.curve.point(t).coords.into())
                        .collect();
                    ToolpathRecord {
                        id: c.id.clone(),
                        params,
                        points: ToolpathPoints::Positions(points),
                        max_chord_error: 0.0,
                        kerf_offset: None,
                    }
                })
                .collect(),
        }
    }

    #[test]
    fn a_scene_from_files_has_every_path() {
        let file = kerf_format::curves::load(fixture("mixed.json")).unwrap();
        let tp = toolpath(&file);
        let scene = Scene::new(&file, &tp, &SceneOptions::default()).unwrap();
        assert_eq!(scene.paths.len(), 4, "one per path");
        for (p, c) in scene.paths.iter().zip(&file.curves) {
            assert_eq!(p.points.len(), 21, "{}", p.id);
            assert_eq!(p.segment_errors.len(), 20, "{}", p.id);
            assert!(p.curve.len() >= 64, "{}: densely sampled", p.id);
            let straight = c.curve.degree() == 1;
            let worst = p.segment_errors.iter().copied().fold(0.0, f64::max);
            assert_eq!(
                worst < 1e-9,
                straight,
                "{}: only the line has no chord error",
                p.id
            );
        }
        assert!(
            scene.subtitle.contains("84 cutting points"),
            "{}",
            scene.subtitle
        );

        let circle = kerf_format::curves::load(fixture("circle.json")).unwrap();
        let e = Scene::new(&circle, &tp, &SceneOptions::default()).unwrap_err();
        assert_eq!(
            e.to_string(),
            "paths[0] (\"v-corner\"): no curve with this id in the curves file",
            "named"
        );
    }

    #[test]
    fn axes_take_the_limits_of_their_machine_only() {
        let machine = Machine::read(fixture("machines/ac_head.json")).unwrap();
        let mut axes = AxesFile {
            machine: machine.name.clone(),
            axes: ["X", "Y", "Z", "A", "C"].map(String::from),
            paths: Vec::new(),
        };
        let chart = AxesChart::new(&axes, Some(&machine)).unwrap();
        assert_eq!(chart.limits[0], Some((-1500.0, 1500.0)), "X");
        assert_eq!(chart.limits[4], None, "C is continuous");
        assert!(chart.limits_known, "from the machine");
        let bare = AxesChart::new(&axes, None).unwrap();
        assert!(
            !bare.limits_known && bare.limits.iter().all(Option::is_none),
            "unknown"
        );
        axes.machine = "another head".into();
        let e = AxesChart::new(&axes, Some(&machine))
            .unwrap_err()
            .to_string();
        assert!(
            e.starts_with("the axes file is for machine another head (tilt A)"),
            "{e}"
        );
    }
}
