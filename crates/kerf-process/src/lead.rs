//! Start points, lead-ins and lead-outs of one contour.

use nalgebra::{Point3, Vector3};

use crate::geometry::Projected;
use crate::{Contour, Pose, ProcessError, Result, Side};

/// Options of the lead-ins, lead-outs and start points.
#[derive(Debug, Clone, Copy, PartialEq)]
#[non_exhaustive]
pub struct LeadOptions {
    /// Length of the straight part of a lead-in, from the pierce point to the arc, mm
    /// (default 2).
    pub lead_in_mm: f64,
    /// Radius of the quarter arc that joins a closed contour tangentially, mm (default 1).
    pub lead_in_radius_mm: f64,
    /// How far the cut runs on past its start on a closed contour, so that no notch is left,
    /// mm (default 0.5).
    pub overcut_mm: f64,
    /// Length of the straight exit into the scrap after the overcut, mm (default 1).
    pub lead_out_mm: f64,
    /// Chord error of the lead-in arc's polyline, mm (default 0.001).
    pub arc_tolerance_mm: f64,
    /// A contour whose first and last points are this close is closed, mm (default 1e-6).
    pub closed_tolerance_mm: f64,
    /// A turn of the contour by more than this at a cutting point is a corner, where no cut
    /// starts, degrees (default 20).
    pub corner_deg: f64,
    /// A lead-in that does not fit the scrap is halved until it does, down to this size
    /// (straight part plus radius), mm; below it the cut pierces on the contour and the plan
    /// says so (default 0.05).
    pub min_lead_mm: f64,
}

impl Default for LeadOptions {
    fn default() -> Self {
        Self {
            lead_in_mm: 2.0,
            lead_in_radius_mm: 1.0,
            overcut_mm: 0.5,
            lead_out_mm: 1.0,
            arc_tolerance_mm: 0.001,
            closed_tolerance_mm: 1e-6,
            corner_deg: 20.0,
            min_lead_mm: 0.05,
        }
    }
}

impl LeadOptions {
    /// Sets [`lead_in_mm`](Self::lead_in_mm): length of the straight part of a lead-in,
    /// from the pierce point to the arc, mm (default 2).
    pub fn with_lead_in_mm(mut self, lead_in_mm: f64) -> Self {
        self.lead_in_mm = lead_in_mm;
        self
    }

    /// Sets [`lead_in_radius_mm`](Self::lead_in_radius_mm): radius of the quarter arc that
    /// joins a closed contour tangentially, mm (default 1).
    pub fn with_lead_in_radius_mm(mut self, lead_in_radius_mm: f64) -> Self {
        self.lead_in_radius_mm = lead_in_radius_mm;
        self
    }

    /// Sets [`overcut_mm`](Self::overcut_mm): how far the cut runs on past its start on a
    /// closed contour, so that no notch is left, mm (default 0.5).
    pub fn with_overcut_mm(mut self, overcut_mm: f64) -> Self {
        self.overcut_mm = overcut_mm;
        self
    }

    /// Sets [`lead_out_mm`](Self::lead_out_mm): length of the straight exit into the scrap
    /// after the overcut, mm (default 1).
    pub fn with_lead_out_mm(mut self, lead_out_mm: f64) -> Self {
        self.lead_out_mm = lead_out_mm;
        self
    }

    /// Sets [`arc_tolerance_mm`](Self::arc_tolerance_mm): chord error of the lead-in arc's
    /// polyline, mm (default 0.001).
    pub fn with_arc_tolerance_mm(mut self, arc_tolerance_mm: f64) -> Self {
        self.arc_tolerance_mm = arc_tolerance_mm;
        self
    }

    /// Sets [`closed_tolerance_mm`](Self::closed_tolerance_mm): a contour whose first and
    /// last points are this close is closed, mm (default 1e-6).
    pub fn with_closed_tolerance_mm(mut self, closed_tolerance_mm: f64) -> Self {
        self.closed_tolerance_mm = closed_tolerance_mm;
        self
    }

    /// Sets [`corner_deg`](Self::corner_deg): a turn of the contour by more than this at a
    /// cutting point is a corner, where no cut starts, degrees (default 20).
    pub fn with_corner_deg(mut self, corner_deg: f64) -> Self {
        self.corner_deg = corner_deg;
        self
    }

    /// Sets [`min_lead_mm`](Self::min_lead_mm): a lead-in that does not fit the scrap is
    /// halved until it does, down to this size (straight part plus radius), mm.
    pub fn with_min_lead_mm(mut self, min_lead_mm: f64) -> Self {
        self.min_lead_mm = min_lead_mm;
        self
    }

    /// With this straight lead-in length and arc radius, mm.
    pub fn with_lead_in(mut self, line_mm: f64, radius_mm: f64) -> Self {
        self.lead_in_mm = line_mm;
        self.lead_in_radius_mm = radius_mm;
        self
    }
    /// With this overcut and lead-out length, mm.
    pub fn with_lead_out(mut self, overcut_mm: f64, lead_out_mm: f64) -> Self {
        self.overcut_mm = overcut_mm;
        self.lead_out_mm = lead_out_mm;
        self
    }

    /// Checks every option: the four lengths of the leads finite and in `[0, 1e4]` mm, the
    /// arc and closed tolerances, the corner angle and the smallest lead finite and in
    /// `(0, 1e4]`. [`crate::plan_cuts`] runs it; a caller may run it before any work.
    ///
    /// # Errors
    /// [`ProcessError::BadOption`] naming the first option out of range.
    pub fn validate(&self) -> Result<()> {
        for (name, v, zero_ok) in [
            ("lead_in_mm", self.lead_in_mm, true),
            ("lead_in_radius_mm", self.lead_in_radius_mm, true),
            ("overcut_mm", self.overcut_mm, true),
            ("lead_out_mm", self.lead_out_mm, true),
            ("arc_tolerance_mm", self.arc_tolerance_mm, false),
            ("closed_tolerance_mm", self.closed_tolerance_mm, false),
            ("corner_deg", self.corner_deg, false),
            ("min_lead_mm", self.min_lead_mm, false),
        ] {
            let ok = v.is_finite() && (v > 0.0 || (zero_ok && v == 0.0)) && v <= 1e4;
            if !ok {
                return Err(ProcessError::BadOption {
                    name,
                    value: v,
                    reason: if zero_ok {
                        "must be finite, >= 0 and <= 1e4"
                    } else {
                        "must be finite, > 0 and <= 1e4"
                    },
                });
            }
        }
        Ok(())
    }
}

/// The entry and exit of one cut at one start point.
#[derive(Debug, Clone, PartialEq)]
pub struct LeadIn {
    /// The cutting point where the cut starts (for a closed contour it also ends there; for an
    /// open one, 0).
    pub start: usize,
    /// The lead-in, from the pierce point up to (not including) the start point; tool axis
    /// the start point's normal. Empty when the cut pierces on the contour.
    pub lead_in: Vec<Pose>,
    /// After the last cutting point of the cut: the overcut along the contour and the exit
    /// into the scrap.
    pub lead_out: Vec<Pose>,
    /// The scale of the lead-in against the options (1 = full size; smaller where the scrap
    /// is too small, e.g. a small hole).
    pub scale: f64,
    /// True if no lead-in fits the scrap and the cut pierces on the contour.
    pub pierce_on_contour: bool,
}

impl LeadIn {
    /// Where the beam pierces.
    pub fn pierce(&self, contour: &[Pose]) -> Pose {
        self.lead_in.first().copied().unwrap_or(contour[self.start])
    }

    /// Where the head is when the cut is done.
    pub fn exit(&self, contour: &[Pose]) -> Pose {
        self.lead_out.last().copied().unwrap_or(if self.start == 0 {
            contour[contour.len() - 1]
        } else {
            contour[self.start]
        })
    }
}

/// The candidate starts of one contour with their leads.
#[derive(Debug, Clone)]
pub(crate) struct Leads {
    pub(crate) closed: bool,
    pub(crate) options: Vec<LeadIn>,
}

impl Leads {
    pub(crate) fn new(
        c: &Contour<'_>,
        projected: Option<&Projected>,
        side: Option<Side>,
        opts: &LeadOptions,
    ) -> Self {
        let Some(poly) = projected else {
            return Self {
                closed: false,
                options: vec![open_leads(c.poses, opts)],
            };
        };
        let side = side.unwrap_or(Side::Right);
        let inside_side = if poly.area > 0.0 {
            Side::Left
        } else {
            Side::Right
        };
        let scrap_inside = side == inside_side;
        let starts = match c.start {
            Some(s) if s + 1 < c.poses.len() => vec![s],
            _ => candidates(c.poses, opts),
        };
        let options = starts
            .into_iter()
            .map(|s| {
                closed_leads(
                    c.poses,
                    s,
                    poly,
                    side,
                    scrap_inside,
                    c.scrap.is_some(),
                    opts,
                )
            })
            .collect();
        Self {
            closed: true,
            options,
        }
    }
}

/// Unit tangent at cutting point `i` of a closed contour (central difference, in the tangent
/// plane of the normal there).
fn closed_tangent(poses: &[Pose], i: usize) -> (Vector3<f64>, Vector3<f64>) {
    let m = poses.len() - 1; // distinct points
    let prev = poses[(i + m - 1) % m].position;
    let next = poses[(i + 1) % m].position;
    let n = poses[i].axis.normalize();
    let mut t = next - prev;
    t -= n * n.dot(&t);
    (t.try_normalize(1e-300).unwrap_or_else(Vector3::x), n)
}

/// Start candidates of a closed contour: cutting points away from corners, on the flattest
/// stretch (discrete curvature within the lowest tenth of its range), at most 16 spread along
/// the contour; if every point is at or next to a corner, the gentlest corner.
fn candidates(poses: &[Pose], opts: &LeadOptions) -> Vec<usize> {
    let m = poses.len() - 1;
    let turn: Vec<(f64, f64)> = (0..m)
        .map(|i| {
            let a = poses[(i + m - 1) % m].position;
            let b = poses[i].position;
            let c = poses[(i + 1) % m].position;
            let (u, v) = (b - a, c - b);
            let angle = u.angle(&v);
            let angle = if angle.is_finite() { angle } else { 0.0 };
            let len = 0.5 * (u.norm() + v.norm());
            (
                angle,
                if len > 0.0 {
                    angle / len
                } else {
                    f64::INFINITY
                },
            )
        })
        .collect();
    let corner = opts.corner_deg.to_radians();
    let near_corner = |i: usize| {
        (0..=2).any(|d| turn[(i + d) % m].0 > corner || turn[(i + m - d) % m].0 > corner)
    };
    let eligible: Vec<usize> = (0..m).filter(|&i| !near_corner(i)).collect();
    if eligible.is_empty() {
        let best = (0..m)
            .min_by(|&a, &b| turn[a].0.total_cmp(&turn[b].0).then(a.cmp(&b)))
            .unwrap_or(0);
        return vec![best];
    }
    let kmin = eligible
        .iter()
        .map(|&i| turn[i].1)
        .fold(f64::INFINITY, f64::min);
    let kmax = eligible.iter().map(|&i| turn[i].1).fold(0.0, f64::max);
    let flat: Vec<usize> = eligible
        .into_iter()
        .filter(|&i| turn[i].1 <= kmin + 0.1 * (kmax - kmin) + 1e-12)
        .collect();
    let step = flat.len().div_ceil(16).max(1);
    flat.into_iter().step_by(step).collect()
}

/// The quarter-arc-and-line lead-in and the overcut-and-exit lead-out of a closed contour
/// starting at `s`, halved until they stay in the scrap.
fn closed_leads(
    poses: &[Pose],
    s: usize,
    poly: &Projected,
    side: Side,
    scrap_inside: bool,
    explicit: bool,
    opts: &LeadOptions,
) -> LeadIn {
    let (t, n) = closed_tangent(poses, s);
    let toward = n.cross(&t) * side.sign();
    let start = poses[s].position;
    let full = opts.lead_in_mm + opts.lead_in_radius_mm;
    let mut scale = 1.0;
    let in_scrap = |p: &Point3<f64>| poly.contains(p) == scrap_inside;
    let m = poses.len() - 1;
    let near = 0.5
        * (poses[(s + 1) % m].position - start)
            .norm()
            .min((poses[(s + m - 1) % m].position - start).norm());
    loop {
        let r = opts.lead_in_radius_mm * scale;
        let l = opts.lead_in_mm * scale;
        let mut pts: Vec<Point3<f64>> = Vec::new();
        if r > 0.0 || l > 0.0 {
            let c = start + toward * r;
            let a = c - t * r;
            pts.push(a + toward * l);
            if r > 0.0 {
                let half = (1.0 - opts.arc_tolerance_mm / r).clamp(-1.0, 1.0).acos();
                let k = ((std::f64::consts::FRAC_PI_2 / (2.0 * half.max(1e-9))).ceil() as usize)
                    .clamp(2, 64);
                for j in 0..k {
                    let phi = std::f64::consts::FRAC_PI_2 * (1.0 - j as f64 / k as f64);
                    pts.push(c + (-toward * phi.cos() - t * phi.sin()) * r);
                }
            }
        }
        // The overcut: along the contour past the start, then the exit into the scrap.
        let (mut out, exit_from, exit_dir) = overcut(poses, s, opts.overcut_mm, side);
        let exit = exit_from + exit_dir * (opts.lead_out_mm * scale);
        // Arc points closer to the start than half the neighbouring chords lie between the
        // contour's tangent and the contour itself, where the chord polygon (within the chord
        // tolerance of the curve) cannot tell the sides apart: the crossing test covers them.
        let planar_in = pts
            .iter()
            .filter(|p| (*p - start).norm() > near)
            .all(&in_scrap)
            && pts.windows(2).all(|w| !poly.crosses(&w[0], &w[1], s))
            && pts
                .last()
                .is_none_or(|p| !poly.crosses(p, &(start + (p - start) * 0.999), s));
        let planar_out = opts.lead_out_mm == 0.0 || (in_scrap(&exit) && poly.distance(&exit) > 0.0);
        let (ok_in, ok_out) = if poly.wraps && explicit && !(planar_in && planar_out) {
            // A loop around a tube: the projection folds the sides onto the contour, so the
            // side is judged in 3D, against the nearest cutting point's own `n x t`. Only for
            // a side the file gives: the projected area's sign says nothing about which end
            // of a tube is waste.
            let side3d = |p: &Point3<f64>| side_in_3d(poses, p, side);
            (
                pts.iter()
                    .filter(|p| (*p - start).norm() > near)
                    .all(side3d),
                opts.lead_out_mm == 0.0 || side3d(&exit),
            )
        } else {
            (planar_in, planar_out)
        };
        if ok_in && ok_out || full * scale < opts.min_lead_mm {
            let fits = ok_in && ok_out;
            if !fits {
                pts.clear();
            }
            if opts.lead_out_mm > 0.0 && fits {
                // The exit keeps the axis the overcut ends with (the start's where there is no
                // overcut): the beam does not turn while it leaves.
                let axis = out.last().map_or(n, |p| p.axis);
                out.push(Pose::at(exit, axis));
            }
            return LeadIn {
                start: s,
                lead_in: pts.iter().map(|&p| Pose::at(p, n)).collect(),
                lead_out: out,
                scale: if fits { scale } else { 0.0 },
                pierce_on_contour: !fits || pts.is_empty(),
            };
        }
        scale *= 0.5;
    }
}

/// True if `p` lies on the `side` of a closed contour in 3D: on the side of `n x t` (times the
/// side's sign) at the contour's nearest cutting point, and off the contour.
fn side_in_3d(poses: &[Pose], p: &Point3<f64>, side: Side) -> bool {
    let m = poses.len() - 1;
    let Some(i) = (0..m).min_by(|&a, &b| {
        (poses[a].position - p)
            .norm_squared()
            .total_cmp(&(poses[b].position - p).norm_squared())
    }) else {
        return false;
    };
    let (t, n) = closed_tangent(poses, i);
    let v = (p - poses[i].position).dot(&(n.cross(&t) * side.sign()));
    v > 1e-9
}

/// The cutting points past `s` up to `length` mm along the contour (the last one interpolated
/// on its chord), with the point and the direction of the exit into the scrap there.
fn overcut(
    poses: &[Pose],
    s: usize,
    length: f64,
    side: Side,
) -> (Vec<Pose>, Point3<f64>, Vector3<f64>) {
    let m = poses.len() - 1;
    let mut out = Vec::new();
    let mut left = length;
    let mut i = s;
    let mut here = poses[s].position;
    while left > 0.0 && out.len() < m {
        let j = (i + 1) % m;
        let next = poses[j].position;
        let d = (next - here).norm();
        if d >= left {
            // The overcut ends inside the segment: the point and the tool axis both at the
            // same fraction of it. (With pose j's axis, the beam stood tilted by up to the
            // segment's whole turn at the overcut's end: 0.54 deg on the saddle in LinuxCNC.)
            let f = left / d;
            let p = here + (next - here) * f;
            let a = poses[i].axis * (1.0 - f) + poses[j].axis * f;
            let a = a.try_normalize(1e-300).unwrap_or_else(|| poses[j].axis);
            out.push(Pose {
                position: p,
                axis: a,
            });
            here = p;
            i = j;
            break;
        }
        out.push(poses[j]);
        left -= d;
        here = next;
        i = j;
    }
    let (t, n) = closed_tangent(poses, i);
    let toward = n.cross(&t) * side.sign();
    // Leave at 45 degrees: forward and into the scrap.
    let dir = (toward + t).normalize();
    (out, here, dir)
}

/// Lead-in and lead-out of an open contour: straight along its tangent extensions.
fn open_leads(poses: &[Pose], opts: &LeadOptions) -> LeadIn {
    let n = poses.len();
    let p0 = poses[0].position;
    let p1 = poses[1].position;
    let a0 = poses[0].axis;
    let t0 = (p1 - p0).try_normalize(1e-300).unwrap_or_else(Vector3::x);
    let len_in = opts.lead_in_mm + opts.lead_in_radius_mm;
    let pe = poses[n - 1].position;
    let pd = poses[n - 2].position;
    let ae = poses[n - 1].axis;
    let te = (pe - pd).try_normalize(1e-300).unwrap_or_else(Vector3::x);
    let len_out = opts.overcut_mm + opts.lead_out_mm;
    LeadIn {
        start: 0,
        lead_in: if len_in > 0.0 {
            vec![Pose::at(p0 - t0 * len_in, a0)]
        } else {
            Vec::new()
        },
        lead_out: if len_out > 0.0 {
            vec![Pose::at(pe + te * len_out, ae)]
        } else {
            Vec::new()
        },
        scale: 1.0,
        pierce_on_contour: len_in == 0.0,
    }
}
