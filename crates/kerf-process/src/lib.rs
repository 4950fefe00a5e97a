//! The laser process around the cut contours, in part coordinates, before the kinematics.
//!
//! A laser does not start a cut on the contour: piercing leaves a crater, so the beam pierces in
//! the scrap, runs a **lead-in** that joins the contour tangentially, cuts the contour, and
//! leaves it through an **overcut and lead-out** so that no notch remains. Holes are cut before
//! the outline around them (a part cut free first would drop or tilt before its holes are cut),
//! and the order between contours keeps the traverses short. This crate decides, from the
//! cutting points with their normals (`(x, y, z, i, j, k)`, as `kerf.toolpath/1` holds them):
//!
//! - which contours are closed, and which closed contours lie inside which ([`plan_cuts`]
//!   projects each closed contour along its mean normal and tests winding numbers);
//! - which side of each contour is scrap: the inside of a hole (a closed contour inside an odd
//!   number of others), the outside of an outline, or the curve's own `scrap` key ([`Side`]);
//! - with a kerf width, the path of each contour offset by half of it toward the scrap
//!   ([`offset`]): outside corners on an arc, inside corners cut back, a loop or a feature
//!   smaller than the kerf refused;
//! - where each closed cut starts: never at a corner, on the flattest stretch, and among those
//!   the point nearest to where the head comes from (a curve may pin it);
//! - the lead-in (a straight line and a tangent quarter arc on the scrap side, in the tangent
//!   plane at the start, shrunk until it stays inside the scrap) and lead-out (an overcut along
//!   the contour and a short exit into the scrap); open contours lead in and out along their
//!   tangent extensions;
//! - the cutting order: holes before the contours enclosing them, nearest neighbour with the
//!   start points chosen on the way, improved by 2-opt moves that keep that precedence, within a
//!   work budget.
//!
//! The derivations and the checks are in `docs/process.md`.

mod geometry;
mod head;
mod lead;
mod offset;
mod order;
mod rapid;
mod side;
mod start;
mod traverse;
mod wall;

pub use head::{
    axis_curvature, check_cut, check_cut_along, rotary_departure_rad, tip_zone_mm, CloseStretch,
    CutClearance, HeadCheckOptions, RESOLUTION_MM, SAMPLE_STEP_MM, STRETCH_SLACK_MM,
};
pub use lead::{LeadIn, LeadOptions};
pub use offset::{offset, OffsetInput, OffsetOptions, OffsetPath};
pub use order::CutPlan;
pub use rapid::{
    in_the_cuts_way, own_surfaces_over_the_head, plan_rapids, rapid_moves, Gap, HeadWitness,
    RapidMoves, TraverseHead,
};
pub use side::{head_lines, HeadLines, HEAD_LINE_POINTS};
pub use start::{index_of_param, prepare_start};
pub use traverse::{
    check_move, plan_traverse, plan_traverse_within, Obstacles, Route, Traverse, TraverseOptions,
};
pub use wall::{wall_axis, Wall};

use geometry::Projected;
use thiserror::Error;

pub use kerf_format::Pose;

/// The side of a contour, seen along the contour's direction with the normal toward the
/// viewer (`kerf.curves/1`'s `scrap` key): `Left` is the side of `normal x tangent`.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Side {
    /// The side of `normal x tangent`.
    Left,
    /// The other side.
    Right,
}

impl Side {
    /// `+1` for left, `-1` for right: the sign of `normal x tangent` toward this side.
    pub fn sign(self) -> f64 {
        match self {
            Side::Left => 1.0,
            Side::Right => -1.0,
        }
    }

    /// The other side.
    pub fn opposite(self) -> Side {
        match self {
            Side::Left => Side::Right,
            Side::Right => Side::Left,
        }
    }

    /// `"left"` or `"right"`.
    pub fn name(self) -> &'static str {
        match self {
            Side::Left => "left",
            Side::Right => "right",
        }
    }
}

/// The file's `scrap` key as a side.
impl From<kerf_format::ScrapSide> for Side {
    fn from(s: kerf_format::ScrapSide) -> Self {
        match s {
            kerf_format::ScrapSide::Left => Side::Left,
            kerf_format::ScrapSide::Right => Side::Right,
        }
    }
}

/// A side as the files write it (`scrap`, a toolpath's `kerf_offset.side`).
impl From<Side> for kerf_format::ScrapSide {
    fn from(s: Side) -> Self {
        match s {
            Side::Left => kerf_format::ScrapSide::Left,
            Side::Right => kerf_format::ScrapSide::Right,
        }
    }
}

/// One cut contour: its cutting points in order, and what the file says of it.
#[derive(Debug, Clone, Copy)]
pub struct Contour<'a> {
    /// The curve's id (for messages).
    pub id: &'a str,
    /// The cutting points with normals, in curve order (a closed contour repeats its first
    /// point at the end).
    pub poses: &'a [Pose],
    /// The scrap side, if the file says (`scrap` key); else it is decided.
    pub scrap: Option<Side>,
    /// The index of the cutting point where a closed cut must start (from the curve's `start`
    /// key); else it is chosen.
    pub start: Option<usize>,
}

/// What can go wrong.
#[derive(Debug, Clone, PartialEq, Error)]
#[non_exhaustive]
pub enum ProcessError {
    /// A contour has fewer than two cutting points or non-finite values. Fix: check the
    /// toolpath.
    #[error("contour \"{id}\": {reason}")]
    BadContour {
        /// The contour's id.
        id: String,
        /// What is wrong.
        reason: String,
    },
    /// An option is out of range. Fix: see [`LeadOptions`].
    #[error("option {name}: {reason} (got {value})")]
    BadOption {
        /// The option.
        name: &'static str,
        /// The value given.
        value: f64,
        /// What is wrong.
        reason: &'static str,
    },
    /// A surface given for the traverse checks is not usable (non-finite vertex, index out of
    /// range, no triangle). Fix: check the surface in the curves file.
    #[error("traverse surface: {reason}")]
    BadSurface {
        /// What is wrong.
        reason: String,
    },
    /// Kerf compensation cannot offset a contour: it bends toward the scrap tighter than half
    /// the kerf (a loop smaller than the kerf), an inside corner's sides or two stretches of
    /// the offset cross (a feature narrower than the kerf), it runs along the tool axis, or the
    /// point budget is spent. Fix: a narrower kerf, or leave the feature out of the cut.
    #[error("contour \"{id}\": kerf compensation of a {kerf_width_mm} mm kerf: {reason}")]
    Compensation {
        /// The contour's id.
        id: String,
        /// The kerf width, mm.
        kerf_width_mm: f64,
        /// Where and why, with the sizes.
        reason: String,
    },
    /// The head comes closer to the part than the cutting clearance along a cut
    /// ([`check_cut`]). Fix: a tilt tolerance or another placement, a smaller clearance, or
    /// accept it as a warning where the head model is known to be pessimistic.
    #[error("path \"{id}\": the head comes too close to the part: {reason}")]
    HeadTooClose {
        /// The path's id.
        id: String,
        /// The stretch, the distance, the surface.
        reason: String,
    },
    /// On every route of a traverse that the machine reaches and whose tip and nozzle line
    /// keep the traverse clearance, the head model comes closer to the part than the cutting
    /// clearance ([`TraverseHead`]). Fix: wider axis limits (a higher retract or safe plane),
    /// another cutting order or placement, or accept it as a warning.
    #[error("the traverse from \"{after}\" to \"{before}\": the head comes too close to the part: {reason}")]
    TraverseHeadTooClose {
        /// The path the traverse leaves.
        after: String,
        /// The path it goes to.
        before: String,
        /// The distance, the point, the surface.
        reason: String,
    },
    /// No traverse route between two cuts keeps the clearance: the retract along the tool
    /// axis, the approach, or every travel route comes too close (details boxed, so that the
    /// error stays small). Fix: a smaller clearance, another placement, or check the tool axes
    /// (one pointing into a pocket).
    #[error("{0}")]
    TraverseBlocked(Box<Blockage>),
}

/// Where and why a traverse found no clear route ([`ProcessError::TraverseBlocked`]).
#[derive(Debug, Clone, PartialEq, Error)]
#[error(
    "traverse from ({:.3}, {:.3}, {:.3}) to ({:.3}, {:.3}, {:.3}): no route keeps the {clearance_mm} mm clearance ({why}); ({:.3}, {:.3}, {:.3}) is {distance_mm:.3} mm from the part",
    from[0], from[1], from[2], to[0], to[1], to[2], at[0], at[1], at[2]
)]
pub struct Blockage {
    /// Where the last cut ends, mm.
    pub from: [f64; 3],
    /// The next pierce point, mm.
    pub to: [f64; 3],
    /// A point too close on the route that came nearest to clearing (its sample farthest from
    /// the part: closer than the clearance where measured so, else within the margin), mm.
    pub at: [f64; 3],
    /// Its distance from the part, mm.
    pub distance_mm: f64,
    /// The clearance asked for, mm.
    pub clearance_mm: f64,
    /// Why, in words: which part of the traverse found no clear way (the retract at the
    /// exit, the approach to the pierce, every travel route, the axis limits, the machine's
    /// rapid swing).
    pub why: String,
}

/// `Result` with [`ProcessError`].
pub type Result<T> = std::result::Result<T, ProcessError>;

/// Plans the process of every contour: sides, start points, lead-ins and lead-outs, and the
/// cutting order. Deterministic: the same input gives the same plan.
///
/// # Errors
/// [`ProcessError::BadContour`], [`ProcessError::BadOption`].
pub fn plan_cuts(contours: &[Contour<'_>], options: &LeadOptions) -> Result<CutPlan> {
    let (projected, inside, sides) = nesting(contours, options)?;
    let n = contours.len();
    let leads: Vec<lead::Leads> = (0..n)
        .map(|i| lead::Leads::new(&contours[i], projected[i].as_ref(), sides[i], options))
        .collect();
    Ok(order::plan(contours, &inside, sides, leads))
}

/// The scrap side of every contour, as [`plan_cuts`] decides it: the curve's own `scrap` key,
/// else the inside of a hole (a closed contour inside an odd number of others) or the outside
/// of an outline; `None` for an open contour, or a loop whose tool axes come within 60 degrees
/// of the plane it is projected onto (round a tube), without a `scrap` key. Kerf compensation
/// ([`offset`]) moves each path toward this side before the cuts are planned.
///
/// # Errors
/// As [`plan_cuts`].
pub fn scrap_sides(contours: &[Contour<'_>], options: &LeadOptions) -> Result<Vec<Option<Side>>> {
    let (projected, _, sides) = nesting(contours, options)?;
    // The inside and outside are told in the plane the contour is projected onto; where a tool
    // axis lies within 60 degrees of that plane (a loop round a tube), the kerf moves along the
    // tube, to a side the winding does not tell.
    Ok(sides
        .into_iter()
        .zip(projected)
        .zip(contours)
        .map(|((side, p), c)| match (c.scrap, p) {
            (None, Some(p))
                if p.wraps
                    || c.poses
                        .iter()
                        .any(|q| q.axis.normalize().dot(&p.normal()).abs() < 0.5) =>
            {
                None
            }
            _ => side,
        })
        .collect())
}

/// The contours checked, projected, nested (which closed contours contain which) and sided.
#[allow(clippy::type_complexity)]
fn nesting(
    contours: &[Contour<'_>],
    options: &LeadOptions,
) -> Result<(Vec<Option<Projected>>, Vec<Vec<usize>>, Vec<Option<Side>>)> {
    options.validate()?;
    for c in contours {
        if c.poses.len() < 2 {
            return Err(ProcessError::BadContour {
                id: c.id.to_string(),
                reason: format!("{} cutting points; a cut needs two", c.poses.len()),
            });
        }
        if !c.poses.iter().all(Pose::is_finite) {
            return Err(ProcessError::BadContour {
                id: c.id.to_string(),
                reason: "a cutting point holds a non-finite value".into(),
            });
        }
    }
    let projected: Vec<Option<Projected>> = contours
        .iter()
        .map(|c| Projected::of_closed(c.poses, options.closed_tolerance_mm))
        .collect();
    // Nesting: which closed contours contain which.
    let n = contours.len();
    let mut inside: Vec<Vec<usize>> = vec![Vec::new(); n]; // inside[a] = contours containing a
    for a in 0..n {
        let Some(pa) = &projected[a] else { continue };
        for b in 0..n {
            if a == b {
                continue;
            }
            let Some(pb) = &projected[b] else { continue };
            if pa.area.abs() < pb.area.abs() && pb.contains_contour(contours[a].poses) {
                inside[a].push(b);
            }
        }
    }
    let sides: Vec<Option<Side>> = (0..n)
        .map(|i| {
            if let Some(s) = contours[i].scrap {
                return Some(s);
            }
            let p = projected[i].as_ref()?;
            // Seen from the normal, a counter-clockwise contour has its inside on the left.
            let inside_side = if p.area > 0.0 {
                Side::Left
            } else {
                Side::Right
            };
            let hole = inside[i].len() % 2 == 1;
            Some(if hole {
                inside_side
            } else {
                inside_side.opposite()
            })
        })
        .collect();
    Ok((projected, inside, sides))
}
