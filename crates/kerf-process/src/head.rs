//! The head against the part while it cuts: the smallest distance between the machine file's
//! head model, standing on every pose of a cut, and the part's surfaces, with a proven lower
//! bound that holds between the poses too.
//!
//! **The head at a pose** `(p, a)` (tip on the surface, unit tool axis toward the head): the
//! solids of revolution of [`kerf_kinematics::Head`] about the line `p + a t`, the nozzle tip
//! at `t = standoff`. A head point is `p + a (standoff + h) + rho (cos phi e1 + sin phi e2)`
//! with `h` its height above the nozzle tip and `rho <= r(h)` the head's radius there.
//!
//! **The tip zone.** The nozzle's lowest part is meant to be near the surface it cuts. The
//! check leaves out the head below `tip_zone_mm` (above the nozzle tip): the lowest height
//! from which, on a plane through the cutting point tilted by up to `max_tilt_deg` against the
//! tool axis, every head point keeps the clearance plus [`STRETCH_SLACK_MM`]. A step of the
//! part lower than the tip zone within the nozzle's radius is not seen (it is inside the
//! nozzle's footprint on the surface, where the beam cuts).
//!
//! **The distance, proven.** The head above the tip zone is covered by cells in cylindrical
//! coordinates `[h0, h1] x [rho0, rho1] x [phi0, phi1]`; a cell lies in the ball about its
//! centre `c` of radius `R = sqrt((dh/2)^2 + (drho/2 + rho1 dphi/2)^2)`, and the distance
//! from the part to any point of the cell is at least `d(c) - R` (the distance to a set is
//! 1-Lipschitz), with `d(c)` the exact point-to-surface distance of
//! [`Obstacles::distance_below`]. A cell whose bound clears is done; one that does not is
//! split along its longest extent; a cell centre inside the head closer than the clearance is a
//! witness that the head comes too close there.
//!
//! **Between poses.** From pose `P = (p, a)` to `Q = (q, b)`, a head point `rho` from the
//! cutting point moves by at most `|p - q| + rho angle(a, b)`, and the whole head by at most
//! `D = |p - q| + sqrt(H^2 + r_max^2) angle(a, b)` (`H` the head's top above the tip, `r_max`
//! its largest radius). The poses are subdivided (tip linear, axis along the great circle)
//! until consecutive samples are within [`SAMPLE_STEP_MM`]; a stretch of samples is checked at
//! its middle sample, each cell with the clearance plus its own motion from it (its farthest
//! point from the cutting point; never more than the largest `D`; plus the machine's tolerance
//! budget for its path's deviation from the chords), and split in two where that does not
//! clear, down to single samples. `docs/process.md` ("The head") has the derivation.

use kerf_kinematics::{Head, Pose};
use nalgebra::{Point3, Unit, UnitQuaternion, Vector3};

use crate::traverse::Obstacles;

/// The largest displacement of any head point between two consecutive samples, mm.
pub const SAMPLE_STEP_MM: f64 = 0.5;

/// Samples between the probes that extend a close stretch from a witness: two witnesses this
/// close make the samples between them close (at most 4 mm of head motion apart).
const RUN_STRIDE: usize = 8;

/// The slack the tip zone keeps on a plane for a stretch of samples checked at once, mm.
pub const STRETCH_SLACK_MM: f64 = 1.0;

/// The radius of the smallest cells at a single sample, mm: a cell this small that neither
/// clears the requirement nor witnesses a head point closer than the clearance keeps its bound.
const CLOSE_CELL_MM: f64 = 0.25;

/// The resolution of the check, mm: a sample with no witness is proven at least the clearance
/// less this (and the slack of its motion) from the part, and a head point closer than the
/// clearance less this is witnessed ([`CutClearance::min_distance_mm`] says what was proven).
pub const RESOLUTION_MM: f64 = 2.0 * CLOSE_CELL_MM;

/// Options of [`check_cut`].
#[derive(Debug, Clone, Copy, PartialEq)]
#[non_exhaustive]
pub struct HeadCheckOptions {
    /// The distance the head must keep from the part while it cuts, mm.
    pub clearance_mm: f64,
    /// The nozzle tip's height above the cutting point along the tool axis, mm.
    pub standoff_mm: f64,
    /// The largest angle between the tool axis and the surface normal the tip zone allows
    /// for, degrees.
    pub max_tilt_deg: f64,
    /// The deviation of the machine's tip path from the chords between poses, mm (the
    /// tolerance budget's non-linearity term).
    pub path_deviation_mm: f64,
    /// How far the machine's tool axis may lie from the poses' own axes, degrees: a program
    /// whose blocks merge several poses holds each pose's axis within its fit's orientation
    /// tolerance only; every head point may then lie that angle times its distance from the
    /// tip farther. Default 0 (one block per pose).
    pub axis_deviation_deg: f64,
    /// The most exact distance queries one cut may make: past it the rest of the cut is not
    /// proven clear ([`CutClearance::proven`] false).
    pub max_queries: usize,
    /// Stop at the first sample witnessed closer than the clearance (its one-sample stretch
    /// the only one reported): for a caller that only needs to know the head does not clear,
    /// such as a traverse trying its routes. Default false (every close stretch, in full).
    pub stop_at_first_close: bool,
    /// Check the head down to its nozzle tip, no tip zone left out: for poses away from the
    /// surface being cut (a traverse's travel). Default false.
    pub whole_head: bool,
}

impl Default for HeadCheckOptions {
    fn default() -> Self {
        Self {
            clearance_mm: 1.0,
            standoff_mm: kerf_kinematics::DEFAULT_STANDOFF_MM,
            max_tilt_deg: 10.0,
            path_deviation_mm: 0.0,
            axis_deviation_deg: 0.0,
            max_queries: 2_000_000,
            stop_at_first_close: false,
            whole_head: false,
        }
    }
}

impl HeadCheckOptions {
    /// Sets [`clearance_mm`](Self::clearance_mm).
    pub fn with_clearance_mm(mut self, clearance_mm: f64) -> Self {
        self.clearance_mm = clearance_mm;
        self
    }
    /// Sets [`standoff_mm`](Self::standoff_mm).
    pub fn with_standoff_mm(mut self, standoff_mm: f64) -> Self {
        self.standoff_mm = standoff_mm;
        self
    }
    /// Sets [`max_tilt_deg`](Self::max_tilt_deg).
    pub fn with_max_tilt_deg(mut self, max_tilt_deg: f64) -> Self {
        self.max_tilt_deg = max_tilt_deg;
        self
    }
    /// Sets [`path_deviation_mm`](Self::path_deviation_mm).
    pub fn with_path_deviation_mm(mut self, path_deviation_mm: f64) -> Self {
        self.path_deviation_mm = path_deviation_mm;
        self
    }
    /// Sets [`axis_deviation_deg`](Self::axis_deviation_deg).
    pub fn with_axis_deviation_deg(mut self, axis_deviation_deg: f64) -> Self {
        self.axis_deviation_deg = axis_deviation_deg;
        self
    }
    /// Sets [`max_queries`](Self::max_queries).
    pub fn with_max_queries(mut self, max_queries: usize) -> Self {
        self.max_queries = max_queries;
        self
    }
    /// Sets [`stop_at_first_close`](Self::stop_at_first_close).
    pub fn with_stop_at_first_close(mut self, stop: bool) -> Self {
        self.stop_at_first_close = stop;
        self
    }
    /// Sets [`whole_head`](Self::whole_head).
    pub fn with_whole_head(mut self, whole: bool) -> Self {
        self.whole_head = whole;
        self
    }
}

/// A run of poses where the head comes closer to the part than the clearance: samples
/// witnessed close, and the samples between two such witnesses at most 8 samples (4 mm of head
/// motion) apart.
#[derive(Debug, Clone, PartialEq)]
pub struct CloseStretch {
    /// The first and last pose index of the stretch (the samples between them included).
    pub poses: [usize; 2],
    /// Its length along the tip's path, mm.
    pub length_mm: f64,
    /// The smallest distance witnessed in it, mm: a point of the head (above the tip zone)
    /// this close to the part at one of its samples (an upper bound of the smallest distance
    /// there; negative: inside the part).
    pub distance_mm: f64,
    /// The height above the nozzle tip of the head point nearest the part, mm.
    pub at_height_mm: f64,
    /// The surface nearest that point.
    pub surface: Option<String>,
    /// That point of the head (workpiece frame): the avoidance tilts away from it.
    pub point: Point3<f64>,
}

/// The head against the part along one cut ([`check_cut`]).
#[derive(Debug, Clone, PartialEq)]
pub struct CutClearance {
    /// A proven lower bound of the distance between the head (above the tip zone) and the
    /// part over the cut, poses and the motion between them, outside the close stretches, mm
    /// (infinite without surfaces). Where no stretch is close it is at least the clearance
    /// less [`RESOLUTION_MM`] and the slack of the motion (half a sample step and the path
    /// deviation).
    pub min_distance_mm: f64,
    /// The pose nearest which that bound was found.
    pub at_pose: usize,
    /// The stretches closer than the clearance, in order.
    pub close: Vec<CloseStretch>,
    /// The height of the tip zone the check leaves out, mm above the nozzle tip.
    pub tip_zone_mm: f64,
    /// Samples checked (poses and the points between them).
    pub samples: usize,
    /// Exact distance queries made.
    pub queries: usize,
    /// False when the check could not be made or finished: see
    /// [`unproven`](Self::unproven).
    pub proven: bool,
    /// Why the cut is not proven: the query budget ran out, a pose or an option is not
    /// usable, or the tip zone reaches past the nozzle (a clearance too large for the head).
    pub unproven: Option<String>,
}

/// Marks `out` unproven: the query budget ran out.
fn spent(out: &mut CutClearance, max_queries: usize) {
    out.proven = false;
    out.unproven = Some(format!(
        "the work budget of {max_queries} distance queries ran out"
    ));
}

/// Why a check cannot be made with these inputs, if it cannot.
fn unusable(head: &Head, poses: &[Pose], opts: &HeadCheckOptions, zone: f64) -> Option<String> {
    let o = opts;
    let usable = o.clearance_mm.is_finite()
        && o.clearance_mm > 0.0
        && o.standoff_mm.is_finite()
        && o.standoff_mm >= 0.0
        && o.max_tilt_deg.is_finite()
        && (0.0..=80.0).contains(&o.max_tilt_deg)
        && o.path_deviation_mm.is_finite()
        && o.path_deviation_mm >= 0.0
        && (0.0..=1f64.to_degrees()).contains(&o.axis_deviation_deg);
    if !usable {
        return Some(format!(
            "the options are not usable (clearance {} mm, standoff {} mm, tilt {} deg, path deviation {} mm, axis deviation {} deg)",
            o.clearance_mm, o.standoff_mm, o.max_tilt_deg, o.path_deviation_mm, o.axis_deviation_deg
        ));
    }
    if head.validate().is_err() {
        return Some("the head model is not valid".into());
    }
    if let Some(k) = poses.iter().position(|p| {
        !(p.position.coords.iter().all(|v| v.is_finite()) && (p.axis.norm() - 1.0).abs() <= 1e-6)
    }) {
        return Some(format!(
            "pose {k} is not finite or its axis not of unit length"
        ));
    }
    let nozzle = head.solids[0].length_mm;
    if zone >= nozzle {
        return Some(format!(
            "the tip zone ({zone:.1} mm above the nozzle tip, where the head keeps the clearance plus {STRETCH_SLACK_MM} mm from a plane tilted by {} deg) reaches past the nozzle ({nozzle} mm): the clearance is too large for this head",
            o.max_tilt_deg
        ));
    }
    None
}

/// The height above the nozzle tip from which the head keeps `clearance + STRETCH_SLACK_MM`
/// from a plane through the cutting point tilted by up to `max_tilt_deg` from the tool axis
/// (0 with [`HeadCheckOptions::whole_head`]).
pub fn tip_zone_mm(head: &Head, opts: &HeadCheckOptions) -> f64 {
    if opts.whole_head {
        return 0.0;
    }
    let (s, c) = opts.max_tilt_deg.to_radians().sin_cos();
    let need = opts.clearance_mm + STRETCH_SLACK_MM;
    let len = head.length_mm();
    let steps = 4096usize;
    let mut zone = 0.0;
    for k in (0..=steps).rev() {
        let h = len * k as f64 / steps as f64;
        let r = head.radius_at(h).unwrap_or(0.0);
        if (opts.standoff_mm + h) * c - r * s < need {
            zone = (len * (k + 1) as f64 / steps as f64).min(len);
            break;
        }
    }
    zone
}

/// One sample: the tip, the unit axis, and the pose before it (or at it).
#[derive(Debug, Clone, Copy)]
struct Sample {
    tip: Point3<f64>,
    axis: Vector3<f64>,
    pose: usize,
    /// True at a pose itself, false between `pose` and the next.
    exact: bool,
    /// Path length from the cut's start, mm.
    s: f64,
}

/// A cell of the head in cylindrical coordinates about the tool axis, inside one solid.
#[derive(Debug, Clone, Copy)]
struct Cell {
    h: [f64; 2],
    rho: [f64; 2],
    phi: [f64; 2],
    /// Its solid: the height of its lower end above the tip, its length and its radii at its
    /// two ends.
    solid: [f64; 4],
}

impl Cell {
    /// The solid's radius at height `h` above the nozzle tip (a frustum: linear).
    fn solid_radius(&self, h: f64) -> f64 {
        let [base, len, r0, r1] = self.solid;
        r0 + (r1 - r0) * ((h - base) / len).clamp(0.0, 1.0)
    }
}

impl Cell {
    /// The radius of the ball about the centre that holds the cell.
    fn radius(&self) -> f64 {
        let dh = (self.h[1] - self.h[0]) / 2.0;
        let planar =
            (self.rho[1] - self.rho[0]) / 2.0 + self.rho[1] * (self.phi[1] - self.phi[0]) / 2.0;
        (dh * dh + planar * planar).sqrt()
    }

    fn split(&self) -> [Cell; 2] {
        let dh = self.h[1] - self.h[0];
        let dr = self.rho[1] - self.rho[0];
        let arc = self.rho[1] * (self.phi[1] - self.phi[0]);
        let mut a = *self;
        let mut b = *self;
        if dh >= dr && dh >= arc {
            let m = (self.h[0] + self.h[1]) / 2.0;
            a.h[1] = m;
            b.h[0] = m;
        } else if dr >= arc {
            let m = (self.rho[0] + self.rho[1]) / 2.0;
            a.rho[1] = m;
            b.rho[0] = m;
        } else {
            let m = (self.phi[0] + self.phi[1]) / 2.0;
            a.phi[1] = m;
            b.phi[0] = m;
        }
        [a, b]
    }
}

/// How far the head may move away from a sample, mm, for a head point `rho` mm from the
/// cutting point (the pivot of the poses' rotations): `lin` of the tip's travel, the path's
/// deviation and half steps, plus `ang` radians of the tool axis' turn (each point moves at
/// most `rho` times that), and never more than `cap`, the whole head's figure (`lin + ang
/// reach`, taken as the sum of the maxima, can exceed the maximum of the sums).
#[derive(Debug, Clone, Copy)]
struct Slack {
    lin: f64,
    ang: f64,
    cap: f64,
}

impl Slack {
    /// The motion of a head point `rho` mm from the cutting point.
    fn at(&self, rho: f64) -> f64 {
        self.cap.min(self.lin + self.ang * rho)
    }

    /// The larger of the two, part by part.
    fn max(self, o: Slack) -> Slack {
        Slack {
            lin: self.lin.max(o.lin),
            ang: self.ang.max(o.ang),
            cap: self.cap.max(o.cap),
        }
    }

    /// Both motions in turn.
    fn plus(self, o: Slack) -> Slack {
        Slack {
            lin: self.lin + o.lin,
            ang: self.ang + o.ang,
            cap: self.cap + o.cap,
        }
    }
}

/// The point of a frustum's meridian section (`solid`: the height of its lower end above the
/// nozzle tip, its length, its radii at its two ends) nearest `(rho, h)`, as `(rho, h)`: the
/// point itself inside, else the nearest point of its bottom, side or top (a zero length: the
/// disc at its height). A solid of
/// revolution's point nearest a point lies in that point's meridian half-plane, so this is
/// the solid's point nearest in space too.
fn nearest_in_solid(solid: [f64; 4], rho: f64, h: f64) -> (f64, f64) {
    let [base, len, r0, r1] = solid;
    let top = base + len;
    if h >= base && h <= top && len > 0.0 && rho <= r0 + (r1 - r0) * ((h - base) / len) {
        return (rho, h);
    }
    let mut best = (f64::INFINITY, (rho, h));
    for ((ax, ay), (bx, by)) in [
        ((0.0, base), (r0, base)),
        ((r0, base), (r1, top)),
        ((r1, top), (0.0, top)),
    ] {
        let (dx, dy) = (bx - ax, by - ay);
        let l2 = dx * dx + dy * dy;
        let t = if l2 > 0.0 {
            (((rho - ax) * dx + (h - ay) * dy) / l2).clamp(0.0, 1.0)
        } else {
            0.0
        };
        let q = (ax + t * dx, ay + t * dy);
        let e = (q.0 - rho).powi(2) + (q.1 - h).powi(2);
        if e < best.0 {
            best = (e, q);
        }
    }
    best.1
}

/// The smallest cell a stretch's check refines to before it splits the stretch instead, mm.
const STRETCH_CELL_MM: f64 = 1.0;

/// What one head placement showed.
#[derive(Debug, Clone, Copy)]
enum Verdict {
    /// Every cell clears the requirement; the least `d - R` found, less each cell's motion.
    Clear(f64),
    /// Not shown clear: for a stretch, the bound of the first cell that did not clear; for a
    /// single sample, the distance of a head point (a cell centre) closer than the clearance;
    /// with the height of that cell and its centre.
    Close {
        bound: f64,
        height: f64,
        point: Point3<f64>,
    },
    /// The query budget ran out.
    Spent,
}

/// The head's cells above the tip zone, before any split: one per solid, four quadrants.
fn initial_cells(head: &Head, zone: f64) -> Vec<Cell> {
    let mut cells = Vec::new();
    let mut base = 0.0;
    for s in &head.solids {
        let top = base + s.length_mm;
        let h0 = base.max(zone);
        if h0 < top {
            let solid = [
                base,
                s.length_mm,
                s.bottom_diameter_mm / 2.0,
                s.top_diameter_mm / 2.0,
            ];
            let mut cell = Cell {
                h: [h0, top],
                rho: [0.0, 0.0],
                phi: [0.0, 0.0],
                solid,
            };
            let r = cell.solid_radius(h0).max(cell.solid_radius(top)).max(1e-9);
            cell.rho = [0.0, r];
            for q in 0..4 {
                let phi0 = q as f64 * std::f64::consts::FRAC_PI_2;
                cell.phi = [phi0, phi0 + std::f64::consts::FRAC_PI_2];
                cells.push(cell);
            }
        }
        base = top;
    }
    cells
}

/// The head at `(tip, axis)` against `obstacles`, each cell required to clear the clearance
/// plus its own motion (`slack` at its farthest point from the cutting point `tip`). With
/// `first_only` the first cell that cannot clear (its centre within that, or a cell down to
/// [`STRETCH_CELL_MM`] that does not) ends the search (a stretch is then split); without it, cells are refined down to [`CLOSE_CELL_MM`], and a cell centre
/// inside the head closer than `clearance` is a witness that the head comes that close.
#[allow(clippy::too_many_arguments)]
fn place_head(
    obstacles: &Obstacles,
    cells0: &[Cell],
    standoff: f64,
    tip: &Point3<f64>,
    axis: &Vector3<f64>,
    slack: Slack,
    clearance: f64,
    first_only: bool,
    queries: &mut usize,
    max_queries: usize,
) -> Verdict {
    let e1 = axis
        .cross(
            &(if axis.x.abs() < 0.6 {
                Vector3::x()
            } else {
                Vector3::y()
            }),
        )
        .normalize();
    let e2 = axis.cross(&e1);
    let point = |h: f64, rho: f64, phi: f64| {
        tip + axis * (standoff + h) + e1 * (rho * phi.cos()) + e2 * (rho * phi.sin())
    };
    let mut stack: Vec<Cell> = cells0.to_vec();
    let mut least = f64::INFINITY;
    let mut close: Option<(f64, f64, Point3<f64>)> = None;
    while let Some(cell) = stack.pop() {
        // A cell wholly outside its solid (beyond its largest radius over the cell's heights).
        let (r_lo, r_hi) = (cell.solid_radius(cell.h[0]), cell.solid_radius(cell.h[1]));
        if cell.rho[0] > r_lo.max(r_hi) {
            continue;
        }
        let r = cell.radius();
        // The cell's motion: its farthest point from the cutting point turns the farthest.
        let moved = slack.at((standoff + cell.h[1]).hypot(cell.rho[1]));
        let need = clearance + moved;
        let hm = (cell.h[0] + cell.h[1]) / 2.0;
        let c = point(
            hm,
            (cell.rho[0] + cell.rho[1]) / 2.0,
            (cell.phi[0] + cell.phi[1]) / 2.0,
        );
        if *queries >= max_queries {
            return Verdict::Spent;
        }
        *queries += 1;
        let d = obstacles.distance_below(&c, r + need);
        // A stretch's cell that does not clear is not refined below `STRETCH_CELL_MM`:
        // splitting the stretch is cheaper than cells that fine.
        if first_only && (d < need || (d < r + need && r <= STRETCH_CELL_MM)) {
            // The stretch does not clear at its middle: it is split.
            close = Some((d - r - moved, hm, c));
            break;
        }
        if d >= r + need {
            least = least.min(d - r - moved);
            continue;
        }
        if r <= CLOSE_CELL_MM {
            // A witness: a head point (the centre, or where it lies outside its solid, the
            // point nearest the centre of the solid's slice at the cell's heights: within `r`
            // of it, since the cell meets that slice, and above the tip zone) closer to the
            // part than the clearance.
            let rho = (cell.rho[0] + cell.rho[1]) / 2.0;
            let phi = (cell.phi[0] + cell.phi[1]) / 2.0;
            let slice = [
                cell.h[0],
                cell.h[1] - cell.h[0],
                cell.solid_radius(cell.h[0]),
                cell.solid_radius(cell.h[1]),
            ];
            let (rw, hw) = nearest_in_solid(slice, rho, hm);
            let (dw, w, hw) = if rw == rho && hw == hm {
                (d, c, hm)
            } else {
                let w = point(hw, rw, phi);
                if *queries >= max_queries {
                    return Verdict::Spent;
                }
                *queries += 1;
                (obstacles.distance_below(&w, clearance), w, hw)
            };
            if dw < clearance {
                close = Some((dw, hw, w));
                break;
            }
            // Within the resolution: every point of the cell is within `r` of the centre and
            // `2 r` of `w`, so at least `max(d - r, dw - 2 r)` from the part; with no witness
            // `dw >= clearance`, so the bound is at least the clearance less `2 r`.
            least = least.min((d - r).max(dw - 2.0 * r) - moved);
            continue;
        }
        let [a, b] = cell.split();
        stack.push(a);
        stack.push(b);
    }
    match close {
        Some((bound, height, point)) => Verdict::Close {
            bound,
            height,
            point,
        },
        None => Verdict::Clear(least),
    }
}

/// The samples of a cut: its poses, and between two poses as many points as keep every head
/// point within [`SAMPLE_STEP_MM`] of the last sample.
fn samples(poses: &[Pose], reach: f64) -> Vec<Sample> {
    let mut out = Vec::with_capacity(poses.len());
    let mut s = 0.0;
    for (k, p) in poses.iter().enumerate() {
        if k > 0 {
            let q = &poses[k - 1];
            let step = (p.position - q.position).norm();
            let angle = q.axis.angle(&p.axis);
            let d = step + reach * angle;
            let n = ((d / SAMPLE_STEP_MM).ceil() as usize).clamp(1, 1 << 16);
            let rot = UnitQuaternion::rotation_between(&q.axis, &p.axis)
                .unwrap_or_else(UnitQuaternion::identity);
            for j in 1..n {
                let t = j as f64 / n as f64;
                let axis = (UnitQuaternion::identity().nlerp(&rot, t) * q.axis).normalize();
                out.push(Sample {
                    tip: q.position + (p.position - q.position) * t,
                    axis,
                    pose: k - 1,
                    exact: false,
                    s: s + step * t,
                });
            }
            s += step;
        }
        out.push(Sample {
            tip: p.position,
            axis: Unit::new_normalize(p.axis).into_inner(),
            pose: k,
            exact: true,
            s,
        });
    }
    out
}

/// The head standing on every pose of one cut (`poses`: tip on the surface, unit tool axis
/// toward the head, workpiece frame) and moving between them, against `obstacles`: the
/// smallest distance proven and the stretches closer than the clearance. Between two poses the
/// tool axis is taken to turn along the great circle; [`check_cut_along`] counts a machine's
/// linear rotary interpolation instead.
pub fn check_cut(
    obstacles: &Obstacles,
    head: &Head,
    poses: &[Pose],
    opts: &HeadCheckOptions,
) -> CutClearance {
    check_cut_along(obstacles, head, poses, &[], opts)
}

/// How far the tool axis may leave the great circle between two poses whose axes are
/// `angle_rad` apart when the machine moves its rotary axes linearly from one to the other and
/// the axis `a(s)` of that move (`s` from 0 to 1) has `|a''| <= curvature` ([`axis_curvature`]
/// for kerf's machines), radians. `a(s)` and the great circle `g(s)` share their ends, so
/// `|a - g| <= max |a'' - g''| / 8` (the error of linear interpolation of `a - g`), with
/// `|g''| = angle^2`; the chord bound is turned into an angle.
pub fn rotary_departure_rad(curvature: f64, angle_rad: f64) -> f64 {
    let chord = (curvature + angle_rad * angle_rad) / 8.0;
    2.0 * (0.5 * chord).min(1.0).asin()
}

/// A bound on `|a''|` for the tool axis `a(s) = R_C(c(s)) R_T(t(s)) z` of a machine whose C
/// axis is the tool axis at tilt 0 and whose tilt axis is at right angles to it (every kerf
/// machine: A/C and fork heads, double tables, head-table, seen in the workpiece frame), with
/// the tilt and C moving linearly by `tilt_step_rad` and `c_step_rad` from a tilt of
/// `tilt_start_rad` to `tilt_start_rad + tilt_step_rad`: the second partial derivatives are
/// `|a_tt| = 1`, `|a_tc| = |cos t| <= 1`, `|a_cc| = |sin t|` (the axis turning about C at its
/// distance `sin t` from it), so `|a''| <= dt^2 + 2 |dt dc| + sin(max |t|) dc^2`.
pub fn axis_curvature(tilt_start_rad: f64, tilt_step_rad: f64, c_step_rad: f64) -> f64 {
    let (dt, dc) = (tilt_step_rad.abs(), c_step_rad.abs());
    let t_max = tilt_start_rad
        .abs()
        .max((tilt_start_rad + tilt_step_rad).abs())
        .min(std::f64::consts::FRAC_PI_2);
    dt * dt + 2.0 * dt * dc + t_max.sin() * dc * dc
}

/// [`check_cut`] for a machine that interpolates its rotary axes linearly between the poses:
/// `axis_curvature[k]` bounds `|a''|` of the tool axis on the move from pose `k` to pose
/// `k + 1` ([`axis_curvature`]), and every head point may then also lie
/// [`rotary_departure_rad`] times its distance from the tip off the great-circle motion the
/// samples follow; each sample stands for that much more motion. Steps the slice does not
/// reach count as great circles.
pub fn check_cut_along(
    obstacles: &Obstacles,
    head: &Head,
    poses: &[Pose],
    axis_curvature: &[f64],
    opts: &HeadCheckOptions,
) -> CutClearance {
    let zone = tip_zone_mm(head, opts);
    let mut out = CutClearance {
        min_distance_mm: f64::INFINITY,
        at_pose: 0,
        close: Vec::new(),
        tip_zone_mm: zone,
        samples: 0,
        queries: 0,
        proven: true,
        unproven: None,
    };
    if let Some(why) = unusable(head, poses, opts, zone) {
        out.proven = false;
        out.unproven = Some(why);
        return out;
    }
    if let Some(k) = axis_curvature
        .iter()
        .position(|t| !(t.is_finite() && *t >= 0.0))
    {
        out.proven = false;
        out.unproven = Some(format!(
            "the tool axis' curvature bound from pose {k} is not a finite size ({})",
            axis_curvature[k]
        ));
        return out;
    }
    let reach = (opts.standoff_mm + head.length_mm()).hypot(head.max_radius_mm());
    let samples = samples(poses, reach);
    out.samples = samples.len();
    let cells0 = initial_cells(head, zone);
    if samples.is_empty() || obstacles.is_empty() {
        return out;
    }
    // The motion from one sample to another: the tip's travel and the axis' turn (a head point
    // `rho` from the cutting point moves at most the travel plus `rho` times the turn).
    let disp = |a: &Sample, b: &Sample| {
        let (lin, ang) = ((a.tip - b.tip).norm(), a.axis.angle(&b.axis));
        Slack {
            lin,
            ang,
            cap: lin + reach * ang,
        }
    };
    let turn = |ang: f64| Slack {
        lin: 0.0,
        ang,
        cap: reach * ang,
    };
    // How far the tool axis may leave the great-circle motion on each step between poses.
    let departure: Vec<f64> = (0..poses.len().saturating_sub(1))
        .map(|k| {
            let curvature = axis_curvature.get(k).copied().unwrap_or(0.0);
            if curvature == 0.0 {
                return 0.0;
            }
            rotary_departure_rad(curvature, poses[k].axis.angle(&poses[k + 1].axis))
        })
        .collect();
    // A fitted block's axis within the fit's orientation tolerance of the poses' own: every
    // head point that much farther, on every sample.
    let axis_slack = turn(opts.axis_deviation_deg.to_radians());
    let step_departure = |k: usize| departure.get(k).copied().unwrap_or(0.0);
    let none = Slack {
        lin: 0.0,
        ang: 0.0,
        cap: 0.0,
    };
    // Half the larger step from each sample to its neighbours, and the rotary departure of
    // the steps it lies on: the motion it stands for.
    let half_step: Vec<Slack> = (0..samples.len())
        .map(|k| {
            let own = &samples[k];
            let leave = if own.exact {
                own.pose
                    .checked_sub(1)
                    .map_or(0.0, step_departure)
                    .max(step_departure(own.pose))
            } else {
                step_departure(own.pose)
            };
            [k.checked_sub(1), (k + 1 < samples.len()).then_some(k + 1)]
                .into_iter()
                .flatten()
                .map(|n| {
                    let d = disp(&samples[n], &samples[k]);
                    Slack {
                        lin: d.lin / 2.0,
                        ang: d.ang / 2.0,
                        cap: d.cap / 2.0,
                    }
                })
                .fold(none, Slack::max)
                .plus(turn(leave))
                .plus(axis_slack)
        })
        .collect();
    let deviation = Slack {
        lin: opts.path_deviation_mm,
        ang: 0.0,
        cap: opts.path_deviation_mm,
    };
    // The head at sample `k`, required to clear the clearance plus its motion `slack`.
    let place = |k: usize, slack: Slack, first_only: bool, queries: &mut usize| {
        place_head(
            obstacles,
            &cells0,
            opts.standoff_mm,
            &samples[k].tip,
            &samples[k].axis,
            slack,
            opts.clearance_mm,
            first_only,
            queries,
            opts.max_queries,
        )
    };
    // Close samples: the witnessed distance, the height and the head point.
    let mut close_at: Vec<Option<(f64, f64, Point3<f64>)>> = vec![None; samples.len()];
    let mut todo = vec![(0usize, samples.len() - 1)];
    while let Some((mut i, mut j)) = todo.pop() {
        // Samples already shown close (from a witness nearby) are not checked again.
        while i <= j && close_at[i].is_some() {
            i += 1;
        }
        while j > i && close_at[j].is_some() {
            j -= 1;
        }
        if i > j || close_at[j].is_some() {
            continue;
        }
        let m = (i + j) / 2;
        if close_at[m].is_some() {
            todo.push((m + 1, j));
            todo.push((i, m - 1));
            continue;
        }
        // Each sample stands for the motion halfway to its neighbours.
        let spread = (i..=j)
            .map(|k| disp(&samples[k], &samples[m]).plus(half_step[k]))
            .fold(none, Slack::max);
        let verdict = place(m, spread.plus(deviation), i != j, &mut out.queries);
        match verdict {
            Verdict::Clear(bound) => {
                if bound < out.min_distance_mm {
                    out.min_distance_mm = bound;
                    out.at_pose = samples[m].pose;
                }
            }
            Verdict::Spent => {
                spent(&mut out, opts.max_queries);
                break;
            }
            Verdict::Close {
                bound,
                height,
                point,
            } if i == j => {
                close_at[m] = Some((bound, height, point));
                if opts.stop_at_first_close {
                    break;
                }
                // Then probes every RUN_STRIDE samples on either side: two witnesses that
                // close make the samples between them part of one close stretch.
                for dir in [1isize, -1] {
                    let mut at = m;
                    loop {
                        let k = at as isize + dir * RUN_STRIDE as isize;
                        if k < 0 || k as usize >= samples.len() || close_at[k as usize].is_some() {
                            break;
                        }
                        let k = k as usize;
                        let probe = place(k, half_step[k].plus(deviation), false, &mut out.queries);
                        let (bound, height, point) = match probe {
                            Verdict::Close {
                                bound,
                                height,
                                point,
                            } => (bound, height, point),
                            Verdict::Clear(_) => break,
                            Verdict::Spent => {
                                spent(&mut out, opts.max_queries);
                                break;
                            }
                        };
                        let (lo, hi) = (at.min(k), at.max(k));
                        for c in &mut close_at[lo..=hi] {
                            if c.is_none() {
                                *c = Some((bound, height, point));
                            }
                        }
                        at = k;
                    }
                }
            }
            Verdict::Close { .. } => {
                // The halves, the first checked first (the stack pops the last pushed).
                todo.push((m + 1, j));
                todo.push((i, m));
            }
        }
    }
    let mut marks: Vec<(usize, f64, f64, Point3<f64>)> = close_at
        .iter()
        .enumerate()
        .filter_map(|(k, c)| c.map(|(b, h, p)| (k, b, h, p)))
        .collect();
    marks.sort_by_key(|m| m.0);
    // Runs of consecutive close samples.
    let mut k = 0;
    while k < marks.len() {
        let mut e = k;
        while e + 1 < marks.len() && marks[e + 1].0 == marks[e].0 + 1 {
            e += 1;
        }
        let run = &marks[k..=e];
        let worst = run
            .iter()
            .min_by(|a, b| a.1.total_cmp(&b.1))
            .copied()
            .unwrap_or(run[0]);
        let (a, b) = (&samples[run[0].0], &samples[run[run.len() - 1].0]);
        out.close.push(CloseStretch {
            poses: [a.pose, if b.exact { b.pose } else { b.pose + 1 }],
            length_mm: b.s - a.s,
            distance_mm: worst.1,
            at_height_mm: worst.2,
            surface: obstacles.nearest(&worst.3).map(|(id, _)| id),
            point: worst.3,
        });
        k = e + 1;
    }
    out
}

#[cfg(test)]
mod tests {
    use super::nearest_in_solid;

    /// The nearest point of a frustum's meridian section against a dense sampling of the
    /// section (its boundary and interior on a 0.01 mm grid): in the section, and no sample
    /// nearer; a point inside is its own nearest.
    #[test]
    fn the_nearest_point_of_a_frustum_section_is_the_nearest() {
        // The default nozzle's slice from 1.35 to 3.35 mm above its tip, and a wide flat cone.
        for solid in [[1.35, 2.0, 1.797, 2.237], [0.0, 1.0, 1.0, 6.0]] {
            let [base, len, r0, r1] = solid;
            let radius = |h: f64| r0 + (r1 - r0) * (h - base) / len;
            let mut samples = Vec::new();
            for i in 0..=200 {
                let h = base + len * i as f64 / 200.0;
                let r = radius(h);
                for j in 0..=200 {
                    samples.push((r * j as f64 / 200.0, h));
                }
            }
            for (rho, h) in [
                (5.0, 2.0),
                (3.0, 4.0),
                (0.5, 0.0),
                (9.0, -1.0),
                (1.0, 1.6),
                (7.0, 0.9),
            ] {
                let (rw, hw) = nearest_in_solid(solid, rho, h);
                assert!(
                    hw >= base - 1e-12 && hw <= base + len + 1e-12 && rw <= radius(hw) + 1e-12,
                    "{solid:?} ({rho}, {h}): ({rw}, {hw}) lies outside"
                );
                let got = (rw - rho).hypot(hw - h);
                let best = samples
                    .iter()
                    .map(|&(x, y)| (x - rho).hypot(y - h))
                    .fold(f64::INFINITY, f64::min);
                assert!(
                    got <= best + 1e-12,
                    "{solid:?} ({rho}, {h}): {got} from ({rw}, {hw}), a sample at {best}"
                );
                if rho <= radius(h) && h >= base && h <= base + len {
                    assert_eq!((rw, hw), (rho, h), "inside: itself");
                }
            }
        }
    }
}
