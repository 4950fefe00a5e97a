//! The cuts of a job (`kerf run`): each contour with its start point, lead-in and lead-out
//! ([`kerf_process`]), in cutting order within each set-up, as one path of poses with a
//! parameter and a point function for the kinematics and the interpolator.
//!
//! A cut path's parameter `u` runs through three stretches: the lead-in (`u < t_s`, the
//! lead-in polyline from the pierce point to the start), the contour (from the start `t_s`
//! to the end of the domain, then for a closed contour on from the beginning shifted by the
//! period `P = t_end - t_0` up to `t_s + P`), and the lead-out (after the cut's end, the
//! overcut and exit polyline). Points inserted by the kinematics against the non-linearity
//! error then lie on the curve on the contour and on the polyline elsewhere.

use kerf_format::CurvesFile;
use kerf_normals::Oriented;
use std::sync::Arc;

use kerf_process::{
    offset, plan_cuts, scrap_sides, Contour, CutPlan, LeadOptions, OffsetInput, OffsetOptions,
    OffsetPath, Pose,
};
use nalgebra::Point3;

use crate::error::Error;
use crate::place::Placed;
use crate::report::{
    CompensationPath, CompensationReport, ProcessReport, ShortenedLead, WallReport,
};

/// A point function of a cut path (part coordinates).
type PointFn = Box<dyn kerf_nurbs::CurvePoint + Sync>;

/// One cut: a contour with its lead-in and lead-out, ready for the kinematics.
pub(crate) struct CutPath {
    /// The index of the contour in the curves file.
    pub(crate) curve: usize,
    /// Lead-in poses, then the cut from its start point, then the lead-out (part
    /// coordinates, the surface's normals).
    pub(crate) poses: Vec<Pose>,
    /// The parameter of every pose (strictly increasing; see the module documentation).
    pub(crate) params: Vec<f64>,
    /// The point at a parameter (part coordinates).
    pub(crate) point: PointFn,
    /// How many of the poses are the lead-in, the cut and the lead-out.
    pub(crate) counts: [usize; 3],
    /// The index of the cutting point where the cut starts.
    pub(crate) start_point: usize,
}

/// The process plan of each set-up, with the curves (indices into the file) it was made for.
pub(crate) type SetupPlans = Vec<(Vec<usize>, CutPlan)>;

/// The cuts of every contour in cutting order (set-up by set-up), with the plans that made
/// them.
/// The curves on a thin wall ([`kerf_process::wall_axis`], at most `max_wall_mm` wide; 0: none):
/// one entry per curve, for those that name exactly one surface and no `scrap` key.
pub(crate) fn walls(
    file: &CurvesFile,
    oriented: &[Oriented],
    max_wall_mm: f64,
) -> Vec<Option<kerf_process::Wall>> {
    file.curves
        .iter()
        .zip(oriented)
        .map(|(c, o)| {
            if max_wall_mm.is_nan()
                || max_wall_mm <= 0.0
                || c.scrap.is_some()
                || c.surfaces.len() != 1
            {
                return None;
            }
            let record = file.surface(&c.surfaces[0])?;
            // NURBS surfaces only (a mesh's normals are per triangle).
            let kerf_format::SurfaceGeometry::Nurbs(n) = &record.geometry else {
                return None;
            };
            let hull: Vec<Point3<f64>> = n.control_points().iter().flatten().copied().collect();
            let normal_near = |q: &Point3<f64>| {
                let c = n.closest_point(q, None);
                n.normal(c.u, c.v)
            };
            kerf_process::wall_axis(&hull, &o.poses(), max_wall_mm, &normal_near)
        })
        .collect()
}

/// The `walls` entries of the report: every curve cut along its wall, with the width found.
pub(crate) fn walls_report(
    file: &CurvesFile,
    walls: &[Option<kerf_process::Wall>],
) -> Vec<WallReport> {
    file.curves
        .iter()
        .zip(walls)
        .filter_map(|(c, w)| {
            let w = w.as_ref()?;
            Some(WallReport {
                id: c.id.clone(),
                width_mm: w.width_mm,
                scrap: w.scrap.name().to_string(),
                reason: format!(
                    "its surface is at most {:.3} mm wide across the contour: a wall through the sheet; the beam runs along the wall, the scrap is where the wall's normal points",
                    w.width_mm
                ),
            })
        })
        .collect()
}

/// With a kerf, the share of the chord tolerance the contour's own chords get; the offset's
/// term (`r (1 - cos alpha)`, at most a few per cent of the tolerance on radii above a
/// millimetre) takes the rest, so that the offset needs no more points than the contour.
pub(crate) const KERF_CONTOUR_SHARE: f64 = 0.9;

/// Kerf compensation of a run: the width and where it came from.
#[derive(Debug, Clone, Copy)]
pub(crate) struct Kerf {
    /// The kerf width, mm.
    pub(crate) width_mm: f64,
    /// Where the width came from, in words.
    pub(crate) source: &'static str,
    /// The chord tolerance the offset paths keep, mm.
    pub(crate) tolerance_mm: f64,
    /// True when the controller compensates (LinuxCNC's `G41.1`/`G42.1`, Sinumerik's
    /// `CUT3DC` with `G41`/`G42`): the paths stay on the contour.
    pub(crate) in_control: bool,
    /// The program's dialect (which of the controllers' compensations).
    pub(crate) dialect: kerf_interp::Dialect,
}

/// What kerf compensation did to one contour.
pub(crate) struct Compensated {
    pub(crate) curve: usize,
    pub(crate) outcome: Outcome,
}

/// How one contour is compensated.
pub(crate) enum Outcome {
    /// Offset in the computer.
    Offset(Arc<OffsetPath>),
    /// By the controller, toward this side.
    InControl(kerf_process::Side),
    /// Not at all, and why (an open contour whose scrap side is not known).
    Uncompensated(String),
}

impl Outcome {
    pub(crate) fn is_compensated(&self) -> bool {
        !matches!(self, Outcome::Uncompensated(_))
    }
}

/// A contour on a thin wall ([`kerf_process::wall_axis`]) is planned with the tool axes along
/// the wall and the scrap where the wall's normal points (`walls`, one entry per curve). With
/// a kerf width, every contour whose scrap side is known is offset by half of it toward the
/// scrap first ([`kerf_process::offset`]), and the cuts are planned on the offset paths.
#[allow(clippy::too_many_arguments)]
pub(crate) fn plan(
    file: &CurvesFile,
    oriented: &[Oriented],
    walls: &[Option<kerf_process::Wall>],
    placed: &Placed,
    starts: &[Option<f64>],
    options: &LeadOptions,
    kerf: Option<&Kerf>,
    source: Option<&std::path::Path>,
) -> Result<(Vec<CutPath>, SetupPlans, Vec<Compensated>), Error> {
    let poses: Vec<Vec<Pose>> = oriented
        .iter()
        .enumerate()
        .map(|(i, o)| match walls.get(i) {
            Some(Some(w)) => w.poses.clone(),
            _ => o.poses(),
        })
        .collect();
    let process_error = |e| Error::Process {
        file: source.map(std::path::Path::to_path_buf),
        source: e,
    };
    let mut cuts = Vec::new();
    let mut plans = Vec::new();
    let mut compensated = Vec::new();
    for setup in &placed.plan.setups {
        let scrap_of = |i: usize| match walls.get(i) {
            Some(Some(w)) => Some(w.scrap),
            _ => file.curves[i].scrap.map(kerf_process::Side::from),
        };
        let contours: Vec<Contour<'_>> = setup
            .paths
            .iter()
            .map(|&i| Contour {
                id: &file.curves[i].id,
                poses: &poses[i],
                scrap: scrap_of(i),
                start: starts[i].map(|t| kerf_process::index_of_param(oriented[i].params(), t)),
            })
            .collect();
        // The offset paths of this set-up, by position in it.
        let offsets = match kerf {
            None => vec![None; contours.len()],
            Some(k) => offset_setup(
                file,
                oriented,
                &poses,
                &setup.paths,
                &contours,
                options,
                k,
                &mut compensated,
            )
            .map_err(process_error)?,
        };
        let offset_poses: Vec<Option<Vec<Pose>>> = offsets
            .iter()
            .map(|o| o.as_ref().map(|p| p.poses.clone()))
            .collect();
        let contours: Vec<Contour<'_>> = contours
            .iter()
            .zip(&offsets)
            .zip(&offset_poses)
            .zip(&setup.paths)
            .map(|(((c, off), op), &i)| match (off, op) {
                (Some(off), Some(op)) => Contour {
                    id: c.id,
                    poses: op,
                    scrap: Some(off.side),
                    start: starts[i].map(|t| off.index_of_source(t)),
                },
                _ => *c,
            })
            .collect();
        let plan = plan_cuts(&contours, options).map_err(process_error)?;
        for &k in &plan.order {
            let i = setup.paths[k];
            let cut = match &offsets[k] {
                None => {
                    let c = file.curves[i].curve.clone();
                    let t = oriented[i].params();
                    let (t0, t1) = (t[0], t[t.len() - 1]);
                    let point = move |u: f64| c.point(u.clamp(t0, t1));
                    cut_path(Box::new(point), t, &poses[i], i, &plan, k)
                }
                Some(off) => {
                    let t: Vec<f64> = (0..off.poses.len()).map(|j| j as f64).collect();
                    let c = file.curves[i].curve.clone();
                    let path = Arc::clone(off);
                    let point = move |u: f64| path.point_at(u, &c);
                    let mut cut = cut_path(Box::new(point), &t, &off.poses, i, &plan, k);
                    // The axes file names the start by the contour's cutting point.
                    cut.start_point = kerf_process::index_of_param(
                        oriented[i].params(),
                        off.source[cut.start_point],
                    );
                    cut
                }
            };
            cuts.push(cut);
        }
        plans.push((setup.paths.clone(), plan));
    }
    Ok((cuts, plans, compensated))
}

/// The offset paths of one set-up's contours (`paths[j]` the curve of `contours[j]`), by
/// position in it, with a kerf `k`: `None` for a contour whose scrap side is not known or that
/// the controller compensates; what each got is pushed onto `compensated`.
///
/// # Errors
/// The offset's refusal (a loop smaller than the kerf, a feature narrower than it, ...).
#[allow(clippy::too_many_arguments)]
fn offset_setup(
    file: &CurvesFile,
    oriented: &[Oriented],
    poses: &[Vec<Pose>],
    paths: &[usize],
    contours: &[Contour<'_>],
    options: &LeadOptions,
    k: &Kerf,
    compensated: &mut Vec<Compensated>,
) -> Result<Vec<Option<Arc<OffsetPath>>>, kerf_process::ProcessError> {
    let sides = scrap_sides(contours, options)?;
    let mut out = Vec::with_capacity(contours.len());
    for (j, &i) in paths.iter().enumerate() {
        let Some(side) = sides[j] else {
            compensated.push(Compensated {
                curve: i,
                outcome: Outcome::Uncompensated("its scrap side is not known (an open contour, or a loop round a tube, without a `scrap` key), so it is cut on the contour itself".into()),
            });
            out.push(None);
            continue;
        };
        if k.in_control {
            compensated.push(Compensated {
                curve: i,
                outcome: Outcome::InControl(side),
            });
            out.push(None);
            continue;
        }
        let input = OffsetInput {
            id: &file.curves[i].id,
            curve: &file.curves[i].curve,
            params: oriented[i].params(),
            poses: &poses[i],
            surface_normals: None,
            scrap: side,
            closed: is_closed(&poses[i], options.closed_tolerance_mm),
        };
        let path = offset(&input, &OffsetOptions::new(k.width_mm, k.tolerance_mm))?;
        let path = Arc::new(path);
        compensated.push(Compensated {
            curve: i,
            outcome: Outcome::Offset(Arc::clone(&path)),
        });
        out.push(Some(path));
    }
    Ok(out)
}

/// True if the contour's last point is within `tol` of its first.
fn is_closed(poses: &[Pose], tol: f64) -> bool {
    let (a, b) = (poses[0], poses[poses.len() - 1]);
    ((a.position.x - b.position.x).powi(2)
        + (a.position.y - b.position.y).powi(2)
        + (a.position.z - b.position.z).powi(2))
    .sqrt()
        <= tol
        && poses.len() >= 4
}

/// One cut from its contour's poses `poses` at parameters `t` (the curve's, or an offset
/// path's indices), with `contour` the point at a parameter in `[t[0], t[n - 1]]`.
fn cut_path(
    contour: PointFn,
    t: &[f64],
    poses: &[Pose],
    curve: usize,
    plan: &CutPlan,
    k: usize,
) -> CutPath {
    let lead = &plan.leads[k];
    let n = t.len();
    let s = lead.start;
    let closed = plan.closed[k];
    let period = t[n - 1] - t[0];
    let cut = plan.cut(k, poses);
    let mut cut_params: Vec<f64> = Vec::with_capacity(cut.len());
    if closed && s > 0 {
        cut_params.extend_from_slice(&t[s..]);
        cut_params.extend(t[1..=s].iter().map(|v| v + period));
    } else {
        cut_params.extend_from_slice(t);
    }
    let u_s = cut_params[0];
    let u_e = cut_params[cut_params.len() - 1];
    let step = (period / n as f64).max((u_s.abs() + u_e.abs() + 1.0) * 1e-12);
    let m = lead.lead_in.len();
    let q = lead.lead_out.len();
    let mut params = Vec::with_capacity(m + cut.len() + q);
    params.extend((0..m).map(|j| u_s - (m - j) as f64 * step));
    params.extend_from_slice(&cut_params);
    params.extend((0..q).map(|j| u_e + (j + 1) as f64 * step));
    let mut all = Vec::with_capacity(params.len());
    all.extend_from_slice(&lead.lead_in);
    all.extend_from_slice(&cut);
    all.extend_from_slice(&lead.lead_out);
    // Polylines of the lead-in (ending at the start) and the lead-out (from the cut's end).
    let pt = |p: &Pose| p.position;
    let lead_in: Vec<Point3<f64>> = lead
        .lead_in
        .iter()
        .chain(std::iter::once(&cut[0]))
        .map(pt)
        .collect();
    let lead_out: Vec<Point3<f64>> = std::iter::once(&cut[cut.len() - 1])
        .chain(&lead.lead_out)
        .map(pt)
        .collect();
    let (t0, t_end) = (t[0], t[n - 1]);
    let in_start = u_s - m as f64 * step;
    let point: PointFn = Box::new(move |u: f64| {
        let along = |poly: &[Point3<f64>], x: f64| {
            let x = x.clamp(0.0, (poly.len() - 1) as f64);
            let j = (x.floor() as usize).min(poly.len().saturating_sub(2));
            let f = x - j as f64;
            if poly.len() == 1 {
                poly[0]
            } else {
                poly[j] + (poly[j + 1] - poly[j]) * f
            }
        };
        if u < u_s && m > 0 {
            along(&lead_in, (u - in_start) / step)
        } else if u > u_e && q > 0 {
            along(&lead_out, (u - u_e) / step)
        } else if u > t_end {
            contour.point_at((u - period).clamp(t0, t_end))
        } else {
            contour.point_at(u.clamp(t0, t_end))
        }
    });
    CutPath {
        curve,
        poses: all,
        params,
        point,
        counts: [m, cut.len(), q],
        start_point: if closed { s } else { 0 },
    }
}

/// The toolpath's `kerf_offset` record of an offset path.
pub(crate) fn kerf_offset_record(p: &OffsetPath) -> kerf_format::KerfOffset {
    kerf_format::KerfOffset {
        offset_mm: p.offset_mm,
        side: p.side.into(),
        params: p.source.clone(),
        points: p.poses.iter().map(Pose::to_array).collect(),
        max_chord_error: p.max_chord_error_mm,
        proven: p.proven,
    }
}

/// The program header's line on kerf compensation: the width and where it came from, or that
/// the path is the contour itself. Only numbers and kerf's own words: no text from a file.
pub(crate) fn kerf_header(kerf: Option<&Kerf>, compensated: &[Compensated]) -> String {
    let Some(k) = kerf else {
        return "kerf compensation: none, no kerf width given: the path is the contour itself"
            .into();
    };
    let done = compensated
        .iter()
        .filter(|c| c.outcome.is_compensated())
        .count();
    let left = compensated.len() - done;
    let rest = if left > 0 {
        format!(", {left} open paths not")
    } else {
        String::new()
    };
    if k.in_control {
        format!(
            "kerf compensation in the controller: {} from {} on {done} paths{rest}",
            k.dialect.compensation_words(k.width_mm),
            k.source
        )
    } else {
        format!(
            "kerf compensation in the computer: kerf {} mm from {}, {done} paths offset {} mm{rest}",
            k.width_mm,
            k.source,
            0.5 * k.width_mm
        )
    }
}

/// The `compensation` object of `report.json`.
pub(crate) fn compensation_report(
    file: &CurvesFile,
    kerf: Option<&Kerf>,
    compensated: &[Compensated],
) -> CompensationReport {
    let Some(k) = kerf else {
        return CompensationReport {
            kerf_width_mm: None,
            source: None,
            mode: None,
            offset_mm: None,
            tolerance_mm: None,
            proven: None,
            paths: None,
            note: "no kerf width (the run's kerf_width_mm, the technology entry's or the machine's process.kerf_width_mm): the path is the contour itself".into(),
        };
    };
    let paths: Vec<CompensationPath> = compensated
        .iter()
        .map(|c| {
            let mut entry = CompensationPath {
                id: file.curves[c.curve].id.clone(),
                side: None,
                offset_mm: 0.0,
                points: None,
                inserted: None,
                max_chord_error_mm: None,
                proven: None,
                outside_corners: None,
                inside_corners: None,
                max_corner_material_mm: None,
                crossing_checked: None,
                in_control: None,
                reason: None,
            };
            match &c.outcome {
                Outcome::InControl(side) => {
                    entry.side = Some(side.name().to_string());
                    entry.offset_mm = 0.5 * k.width_mm;
                    entry.in_control = Some(true);
                }
                Outcome::Offset(p) => {
                    entry.side = Some(p.side.name().to_string());
                    entry.offset_mm = p.offset_mm;
                    entry.points = Some(p.poses.len());
                    entry.inserted = Some(p.inserted);
                    entry.max_chord_error_mm = Some(p.max_chord_error_mm);
                    entry.proven = Some(p.proven);
                    entry.outside_corners = Some(p.outside_corners);
                    entry.inside_corners = Some(p.inside_corners);
                    entry.max_corner_material_mm = Some(p.max_corner_material_mm);
                    entry.crossing_checked = Some(p.crossing_checked);
                }
                Outcome::Uncompensated(why) => entry.reason = Some(why.clone()),
            }
            entry
        })
        .collect();
    CompensationReport {
        kerf_width_mm: Some(k.width_mm),
        source: Some(k.source.to_string()),
        mode: Some(if k.in_control { "controller" } else { "computer" }.to_string()),
        offset_mm: Some(0.5 * k.width_mm),
        tolerance_mm: Some(k.tolerance_mm),
        proven: Some(!compensated.is_empty() && compensated.iter().all(|c| matches!(&c.outcome, Outcome::Offset(p) if p.proven))),
        paths: Some(paths),
        note: "in the computer, each path moved half the kerf toward its scrap side, at right angles to the path and the tool axis; outside corners swung round on an arc about the corner, inside corners cut back to where the offsets cross (the round beam leaves max_corner_material_mm there); proven: every chord within the tolerance of the exact offset (on flat contours at a fixed tool axis by the tangents' cone, elsewhere by a bound of the offset direction's second derivative along the chord), else measured at 15 points per chord; in the controller, the program holds the contours with the controller's compensation from the lead-in's first move on: LinuxCNC G41.1/G42.1 D<kerf>, G40 before the beam's off codes; Sinumerik CUT3DC, OFFN=<kerf/2> with G41/G42, G40 after the beam is off (docs/process.md, Kerf compensation)".into(),
    }
}

/// The controller's compensation of every cut (`cuts[k]`, solved as `solved[k]`): the side
/// for those the controller compensates, with a lead-in whose first move is longer than half
/// the kerf (the controller's entry move); for LinuxCNC also checked to stand the beam
/// vertical (tool axis `+z`) with the tilt axis at 0 and C still along the whole cut, lead-in
/// and lead-out included (`G41.1` offsets X and Y only; Sinumerik's `CUT3DC` offsets at right
/// angles to the path and the tool orientation, whatever it is); `None` for the others.
///
/// # Errors
/// [`kerf_process::ProcessError::Compensation`] for a cut the controller cannot compensate,
/// with the ranges of its axes.
pub(crate) fn controller_compensation(
    file: &CurvesFile,
    kerf: Option<&Kerf>,
    compensated: &[Compensated],
    cuts: &[CutPath],
    solved: &[kerf_kinematics::SolvedPath],
) -> Result<Vec<Option<kerf_interp::CutterCompensation>>, kerf_process::ProcessError> {
    let Some(k) = kerf.filter(|k| k.in_control) else {
        return Ok(vec![None; cuts.len()]);
    };
    let side_of = |curve: usize| {
        compensated.iter().find_map(|c| match c.outcome {
            Outcome::InControl(side) if c.curve == curve => Some(side),
            _ => None,
        })
    };
    cuts.iter()
        .zip(solved)
        .map(|(cut, s)| {
            let Some(side) = side_of(cut.curve) else {
                return Ok(None);
            };
            let range = |f: &dyn Fn(&kerf_kinematics::Axes) -> f64| {
                s.axes.iter().map(f).fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), v| {
                    (lo.min(v), hi.max(v))
                })
            };
            let tilt = range(&|a| a.tilt);
            let c = range(&|a| a.c);
            let vertical = s.poses.iter().all(|p| p.axis.z >= 1.0 - 1e-12);
            let any_orientation = !k.dialect.compensation_xy_only();
            if !(any_orientation
                || vertical && tilt.0.abs() <= 1e-9 && tilt.1.abs() <= 1e-9 && c.1 - c.0 <= 1e-9)
            {
                return Err(kerf_process::ProcessError::Compensation {
                    id: file.curves[cut.curve].id.clone(),
                    kerf_width_mm: k.width_mm,
                    reason: format!(
                        "the controller's compensation (G41.1/G42.1) offsets X and Y only: it needs the beam vertical and the rotary axes still along the whole cut, here the tilt axis runs over [{:.6}, {:.6}] deg and C over [{:.6}, {:.6}] deg; compensate in the computer instead",
                        tilt.0, tilt.1, c.0, c.1
                    ),
                });
            }
            // The controller engages on the lead-in's first move (the entry move), which must
            // be longer than the compensation's radius at right angles to the tool axis (the
            // plane the offset is in: X and Y for LinuxCNC's vertical beam); the G-code writer
            // refuses an entry move fitted as an arc.
            let [m, _, _] = cut.counts;
            let entry = if m > 0 {
                let (a, b) = (cut.poses[0], cut.poses[1]);
                let (d, u) = (b.position - a.position, a.axis.normalize());
                (d - u * d.dot(&u)).norm()
            } else {
                0.0
            };
            // A NaN length (a degenerate axis) is refused too.
            if entry.is_nan() || entry <= 0.5 * k.width_mm {
                return Err(kerf_process::ProcessError::Compensation {
                    id: file.curves[cut.curve].id.clone(),
                    kerf_width_mm: k.width_mm,
                    reason: format!(
                        "the controller engages its compensation on the lead-in's first move, which must be a line longer than half the kerf ({} mm) at right angles to the tool axis; here it is {entry:.4} mm{}: give a longer lead-in or compensate in the computer",
                        0.5 * k.width_mm,
                        if m == 0 { " (no lead-in)" } else { "" }
                    ),
                });
            }
            Ok(Some(kerf_interp::CutterCompensation {
                left: side == kerf_process::Side::Left,
                kerf_width_mm: k.width_mm,
            }))
        })
        .collect()
}

/// `kerf.axes/1` with the lead-in and lead-out of every path kept apart from its cut (the
/// contract's `lead_in`, `lead_out` and `start_point` keys): `solved[k]` is the solved
/// `cuts[k]`, and `axes.paths[k]` was made from it.
pub(crate) fn split_axes(
    axes: &mut kerf_kinematics::AxesFile,
    cuts: &[CutPath],
    solved: &[kerf_kinematics::SolvedPath],
) {
    for ((p, cut), s) in axes.paths.iter_mut().zip(cuts).zip(solved) {
        let [m, c, _] = cut.counts;
        let first = s.source.iter().position(|v| *v == Some(m));
        let last = s.source.iter().position(|v| *v == Some(m + c - 1));
        let (Some(a), Some(b)) = (first, last) else {
            continue;
        };
        let part = |r: std::ops::Range<usize>| kerf_kinematics::AxesMove {
            positions: p.positions[r.clone()].to_vec(),
            poses: p.poses[r].to_vec(),
        };
        let len = p.poses.len();
        let lead_in = (a > 0).then(|| part(0..a));
        let lead_out = (b + 1 < len).then(|| part(b + 1..len));
        p.positions = p.positions[a..=b].to_vec();
        p.poses = p.poses[a..=b].to_vec();
        p.inserted = s.source[a..=b].iter().filter(|v| v.is_none()).count();
        p.lead_in = lead_in;
        p.lead_out = lead_out;
        p.start_point = Some(cut.start_point);
    }
}

/// The length of the polyline through the poses' points, mm.
pub(crate) fn polyline_length(p: &[Pose]) -> f64 {
    p.windows(2)
        .map(|w| {
            ((w[1].position.x - w[0].position.x).powi(2)
                + (w[1].position.y - w[0].position.y).powi(2)
                + (w[1].position.z - w[0].position.z).powi(2))
            .sqrt()
        })
        .sum()
}

/// The `process` object of `report.json`: pierces, lengths, order and what each cut got.
pub(crate) fn report(file: &CurvesFile, cuts: &[CutPath], plans: &SetupPlans) -> ProcessReport {
    let len = polyline_length;
    let cut_length: f64 = cuts
        .iter()
        .map(|c| len(&c.poses[c.counts[0]..c.counts[0] + c.counts[1]]))
        .sum();
    let lead_length: f64 = cuts
        .iter()
        .map(|c| len(&c.poses[..c.counts[0] + 1]) + len(&c.poses[c.counts[0] + c.counts[1] - 1..]))
        .sum();
    let mut holes = Vec::new();
    let mut shortened = Vec::new();
    let mut on_contour = Vec::new();
    let mut traverse = 0.0;
    let mut file_order = 0.0;
    for (paths, plan) in plans {
        traverse += plan.traverse_mm;
        file_order += plan.file_order_traverse_mm;
        for (k, &i) in paths.iter().enumerate() {
            let id = file.curves[i].id.clone();
            if plan.is_hole(k) {
                holes.push(id.clone());
            }
            let l = &plan.leads[k];
            if l.pierce_on_contour {
                on_contour.push(id);
            } else if l.scale < 1.0 {
                shortened.push(ShortenedLead { id, scale: l.scale });
            }
        }
    }
    ProcessReport {
        pierces: cuts.len(),
        order: cuts.iter().map(|c| file.curves[c.curve].id.clone()).collect(),
        holes_cut_first: holes,
        cut_length_mm: cut_length,
        lead_length_mm: lead_length,
        traverse_mm: traverse,
        file_order_traverse_mm: file_order,
        traverse_saved_mm: file_order - traverse,
        lead_ins_shortened: shortened,
        pierce_on_contour: on_contour,
        traverse_note: "straight distances from each cut's exit to the next pierce point, in part coordinates, within each set-up; the program adds the retract and approach along the tool axes".into(),
    }
}

/// Per cut (indexed like `cuts`): true for a small hole of a technology's small-hole rule: a
/// closed contour the plans call a hole whose diameter (the largest distance between two of
/// its cutting points) is at most `max_diameter_mm`. A contour of more than
/// [`SMALL_HOLE_SAMPLES`] points is measured on every k-th point, which can only make a hole
/// look smaller by the gap between sampled points: a few hundredths of a millimetre on the
/// holes the rule is for.
pub(crate) fn small_holes(cuts: &[CutPath], plans: &SetupPlans, max_diameter_mm: f64) -> Vec<bool> {
    let closed = closed_contours(plans);
    cuts.iter()
        .map(|c| {
            if closed.get(&c.curve) != Some(&true) {
                return false;
            }
            let contour = &c.poses[c.counts[0]..c.counts[0] + c.counts[1]];
            let stride = contour.len().div_ceil(SMALL_HOLE_SAMPLES).max(1);
            let pts: Vec<&Pose> = contour.iter().step_by(stride).collect();
            let mut d2 = 0.0f64;
            for (a, p) in pts.iter().enumerate() {
                for q in &pts[a + 1..] {
                    d2 = d2.max(
                        (p.position.x - q.position.x).powi(2)
                            + (p.position.y - q.position.y).powi(2)
                            + (p.position.z - q.position.z).powi(2),
                    );
                }
            }
            // A hole of exactly the rule's diameter is one (its points lie on the circle, a
            // rounding either way).
            d2.sqrt() <= max_diameter_mm + 1e-6
        })
        .collect()
}

/// The closed contours of the plans (curve index in the file) and whether each is a hole.
fn closed_contours(plans: &SetupPlans) -> std::collections::HashMap<usize, bool> {
    plans
        .iter()
        .flat_map(|(paths, plan)| {
            paths
                .iter()
                .enumerate()
                .filter(|&(k, _)| plan.closed[k])
                .map(move |(k, &i)| (i, plan.is_hole(k)))
        })
        .collect()
}

/// The most cutting points [`small_holes`] compares pairwise per contour.
const SMALL_HOLE_SAMPLES: usize = 512;

/// The micro-joints of every cut (indexed like `cuts`): `[start, end]`, mm along the cut's
/// poses from its first (the lead-in's start), and one warning per joint there was no room
/// for. Closed contours only: each part's outline gets `max(1, round(P / spacing))` joints,
/// `P` its length, and each cut-out `floor(P / spacing)` (none on one shorter than the
/// spacing: its slug may fall). Joint `k` is centred at `(k + 1/2) P / n` from the contour's
/// start, or as near as its share of the contour allows (0.25 mm steps) so that no corner (a
/// turn of more than [`JOINT_CORNER_DEG`]) lies within 1 mm of it and it keeps its length
/// plus 1 mm from the contour's start and end (the lead-in joins there, the overcut runs
/// past it).
pub(crate) fn micro_joints(
    file: &CurvesFile,
    cuts: &[CutPath],
    plans: &SetupPlans,
    length_mm: f64,
    spacing_mm: f64,
) -> (Vec<Vec<[f64; 2]>>, Vec<String>) {
    let kind = closed_contours(plans);
    let mut warnings = Vec::new();
    let joints = cuts
        .iter()
        .map(|c| {
            let Some(&hole) = kind.get(&c.curve) else {
                return Vec::new();
            };
            let p = &c.poses;
            let mut cum = vec![0.0];
            for w in p.windows(2) {
                let d = ((w[1].position.x - w[0].position.x).powi(2)
                    + (w[1].position.y - w[0].position.y).powi(2)
                    + (w[1].position.z - w[0].position.z).powi(2))
                .sqrt();
                cum.push(cum[cum.len() - 1] + d);
            }
            let (first, last) = (c.counts[0], c.counts[0] + c.counts[1] - 1);
            let (s_in, s_out) = (cum[first], cum[last]);
            let perimeter = s_out - s_in;
            let n = if hole {
                (perimeter / spacing_mm).floor() as usize
            } else {
                ((perimeter / spacing_mm).round() as usize).max(1)
            };
            if n == 0 {
                return Vec::new();
            }
            // Corners of the contour, as distances along the cut.
            let dir = |a: &Pose, b: &Pose| {
                b.position - a.position
            };
            let corners: Vec<f64> = (first + 1..last)
                .filter(|&i| {
                    let (u, v) = (dir(&p[i - 1], &p[i]), dir(&p[i], &p[i + 1]));
                    u.norm() > 0.0
                        && v.norm() > 0.0
                        && u.angle(&v) > JOINT_CORNER_DEG.to_radians()
                })
                .map(|i| cum[i])
                .collect();
            let fits = |centre: f64| {
                let (a, b) = (centre - 0.5 * length_mm, centre + 0.5 * length_mm);
                let lo = corners.partition_point(|&s| s < a - 1.0);
                a >= s_in + length_mm + 1.0
                    && b <= s_out - length_mm - 1.0
                    && corners.get(lo).is_none_or(|&s| s > b + 1.0)
            };
            let share = perimeter / n as f64;
            let steps = (0.5 * share / 0.25).floor() as usize;
            let mut out = Vec::new();
            for k in 0..n {
                let target = s_in + (k as f64 + 0.5) * share;
                let found = (0..=steps)
                    .flat_map(|i| [target + 0.25 * i as f64, target - 0.25 * i as f64])
                    .find(|&centre| fits(centre));
                match found {
                    Some(centre) => {
                        out.push([centre - 0.5 * length_mm, centre + 0.5 * length_mm])
                    }
                    None => warnings.push(format!(
                        "{}: no room for micro-joint {} of {} away from the corners and the lead-in (left out)",
                        file.curves[c.curve].id,
                        k + 1,
                        n
                    )),
                }
            }
            out
        })
        .collect();
    (joints, warnings)
}

/// A turn of the contour above this is a corner no micro-joint may lie within 1 mm of,
/// degrees (the start point's corner rule).
pub(crate) const JOINT_CORNER_DEG: f64 = 20.0;

/// The point at `s` mm along the poses `p` (the first pose's, linearly between poses).
pub(crate) fn point_along(p: &[[f64; 3]], s: f64) -> [f64; 3] {
    let mut left = s;
    for w in p.windows(2) {
        let d = ((w[1][0] - w[0][0]).powi(2)
            + (w[1][1] - w[0][1]).powi(2)
            + (w[1][2] - w[0][2]).powi(2))
        .sqrt();
        if left <= d && d > 0.0 {
            let f = left / d;
            return std::array::from_fn(|k| w[0][k] + f * (w[1][k] - w[0][k]));
        }
        left -= d;
    }
    p.last().copied().unwrap_or([0.0; 3])
}
