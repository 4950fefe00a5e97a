//! [`Report`]: what a run did, stage by stage, as typed fields; `report.json` is its
//! serialization (`docs/formats.md`, "report.json", names every key).
//!
//! Each stage's figures are a struct of their own; the JSON keys come in the order of the
//! fields (the maps `tolerance_budget_mm` and `traverses.routes` sorted by name). Sections that only exist with an option are `Option`s,
//! `null` without it (`technology`, `micro_joints`, `kinematics.tilt`); sections that say they
//! did nothing without one (`compensation`, `head`, `traverses`) carry their flag
//! (`checked: false`) or a `null` `kerf_width_mm` and a `note`, and leave their other figures
//! `None`, which the JSON leaves out. Lengths are mm, times s, angles degrees, as each field's
//! name says. Points are `[x, y, z]` in the set-up's workpiece frame unless a field says
//! otherwise.

use std::collections::BTreeMap;

use kerf_discretize::Discretization;
use kerf_format::toolpath::ToolpathFile;
use kerf_format::CurvesFile;
use kerf_interp::{Dialect, GcodeOptions, Motion, ProcessCodes};
use kerf_kinematics::SolvedPath;
use kerf_normals::Oriented;
use serde::Serialize;

use crate::timing::Timings;

/// Everything a run reports ([`crate::Output::report`]).
#[derive(Debug, Clone, Serialize)]
#[non_exhaustive]
pub struct Report {
    /// The input file's name as given, `None` for a job built in memory.
    pub input: Option<String>,
    /// The machine's name (`kerf.machine/1` `name`).
    pub machine: String,
    /// Every warning of the run, as the CLI prints them: the input's assumptions (`input: `),
    /// the curves and machine files' near-miss keys (`curves file: `, `machine file: `), then
    /// the run's own (traverses that could not be checked, ...).
    pub warnings: Vec<String>,
    /// The program's tolerance budget, mm, by term (`chord`, `linearization`, `fit`,
    /// `interpolation_chord`, `controller_blending`, ...; `None` for a term not known) and its
    /// `total`.
    pub tolerance_budget_mm: BTreeMap<String, Option<f64>>,
    /// The program files and their process codes.
    pub program: ProgramReport,
    /// Kerf compensation.
    pub compensation: CompensationReport,
    /// The technology entry used (`None` without a technology table).
    pub technology: Option<TechnologyReport>,
    /// The micro-joints left uncut (`None` without micro-joints).
    pub micro_joints: Option<MicroJointsReport>,
    /// The head against the part along the cuts.
    pub head: HeadReport,
    /// The cutting points.
    pub discretize: DiscretizeReport,
    /// The surface normals.
    pub normals: NormalsReport,
    /// The machine axes.
    pub kinematics: KinematicsReport,
    /// Where the part went on the machine, and which side each contour is cut from.
    pub placement: PlacementReport,
    /// The cuts: pierces, order, leads.
    pub process: ProcessReport,
    /// The traverses between the cuts and how they were checked.
    pub traverses: TraversesReport,
    /// The planned motion.
    pub interpolation: InterpolationReport,
    /// Wall seconds of the run's last pass through the stages: not the CLI's reading of its
    /// files, nor the `--place auto` searches a wider margin replaced (those are in
    /// [`timings`](Self::timings) as `earlier placements`).
    pub seconds: f64,
    /// Wall and CPU seconds per stage, the CLI's `read` and `write` included once it adds them.
    pub timings: Timings,
}

/// `program`: the files written and the process codes they use.
#[derive(Debug, Clone, Serialize)]
#[non_exhaustive]
pub struct ProgramReport {
    /// The G-code dialect (`generic`, `linuxcnc`, `sinumerik`, ...).
    pub dialect: String,
    /// The program lines that switch the beam on (the machine file's, or the dialect's own).
    pub beam_on: Vec<String>,
    /// The lines that switch it off.
    pub beam_off: Vec<String>,
    /// The dwell at each pierce, s.
    pub pierce_dwell_s: f64,
    /// The pierce height above the surface along the tool axis, mm.
    pub pierce_standoff_mm: f64,
    /// Cuts in all programs (each a beam-on stretch between rapids).
    pub cuts: usize,
    /// The program files, one per set-up (`program.nc`, or `program-1.nc`, ...).
    pub files: Vec<String>,
}

/// `discretize`: the certified cutting points.
#[derive(Debug, Clone, Serialize)]
#[non_exhaustive]
pub struct DiscretizeReport {
    /// Curves in the input.
    pub curves: usize,
    /// Chords of all paths.
    pub segments: usize,
    /// The estimate of the fewest chords any discretization within the tolerance needs, from
    /// the curvature at the points (paper 004's `N*`).
    pub n_star: f64,
    /// The largest certified chord error, mm.
    pub max_chord_error: f64,
    /// C0 corners kept as cutting points.
    pub c0_breaks: usize,
}

/// `normals`: the tool axes from the surfaces.
#[derive(Debug, Clone, Serialize)]
#[non_exhaustive]
pub struct NormalsReport {
    /// Cutting points with a normal.
    pub points: usize,
    /// Points inserted where the normal turned more than the step allows.
    pub inserted: usize,
    /// The largest distance from a cutting point to its surface, mm.
    pub max_surface_distance: f64,
    /// Normal jumps (C0 creases of the surface under the path).
    pub jumps: usize,
    /// Curves that name no surface (their axis is +z).
    pub curves_without_surface: usize,
}

/// `kinematics`: the machine axes of the poses.
#[derive(Debug, Clone, Serialize)]
#[non_exhaustive]
pub struct KinematicsReport {
    /// Poses solved (leads and inserted points included).
    pub poses: usize,
    /// Poses inserted for the non-linearity of the rotary axes.
    pub inserted: usize,
    /// The largest rotary step between two cutting points, degrees.
    pub max_rotary_step_between_cutting_points: f64,
    /// The largest distance of the tip's path, with the axes moving linearly, from the
    /// chord, mm.
    pub max_linearization_error: f64,
    /// Poses at a singularity (the pole), where C was held.
    pub pole_points: usize,
    /// The largest tip error that holding C at the pole introduced, mm.
    pub pole_tip_error: f64,
    /// What the tilt tolerance did (`None` without one).
    pub tilt: Option<TiltTotals>,
}

/// `kinematics.tilt`: the tool axes chosen within the tilt tolerance.
#[derive(Debug, Clone, Serialize)]
#[non_exhaustive]
pub struct TiltTotals {
    /// The tolerance, degrees.
    pub tolerance_deg: f64,
    /// The largest angle between a tool axis and its surface normal, degrees.
    pub max_deg: f64,
    /// The path where it is.
    pub max_path: Option<String>,
    /// Its cutting point, mm (`None` where no path has a tilt).
    pub max_at_mm: Option<[f64; 3]>,
    /// The rotary travel `sum |d tilt| + |d C|` of the exact normals, degrees.
    pub rotary_travel_exact_deg: f64,
    /// The rotary travel of the chosen axes, degrees.
    pub rotary_travel_deg: f64,
    /// The same per path whose axes the tolerance chose.
    pub paths: Vec<TiltPath>,
}

/// One path of [`TiltTotals::paths`].
#[derive(Debug, Clone, Serialize)]
#[non_exhaustive]
pub struct TiltPath {
    /// The path's id.
    pub id: String,
    /// The largest angle between its axes and their normals, degrees.
    pub max_deg: f64,
    /// Where, mm (`NaN`, written `null`, where the point is not a cutting point).
    pub at_mm: [f64; 3],
    /// Rotary travel of the exact normals, degrees.
    pub rotary_travel_exact_deg: f64,
    /// Rotary travel of the chosen axes, degrees.
    pub rotary_travel_deg: f64,
    /// Strings of points whose smoothing went over the tolerance and kept the exact normals.
    pub strings_over_budget: usize,
}

/// `compensation`: the kerf offset.
#[derive(Debug, Clone, Serialize)]
#[non_exhaustive]
pub struct CompensationReport {
    /// The kerf width, mm (`None`: no kerf, the path is the contour itself).
    pub kerf_width_mm: Option<f64>,
    /// Where the width came from (`the run's kerf_width_mm`, `technology entry`, `machine file
    /// process.kerf_width_mm`).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub source: Option<String>,
    /// `computer` (kerf offsets the path) or `controller` (LinuxCNC's `G41.1`/`G42.1`,
    /// Sinumerik's `CUT3DC` with `G41`/`G42`).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub mode: Option<String>,
    /// Half the kerf, mm.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub offset_mm: Option<f64>,
    /// The chord tolerance the offset paths keep, mm.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub tolerance_mm: Option<f64>,
    /// Every path offset with a proven certificate.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub proven: Option<bool>,
    /// Per contour, set-up by set-up in each set-up's order of paths (`None` without a kerf).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub paths: Option<Vec<CompensationPath>>,
    /// What the figures mean.
    pub note: String,
}

/// One path of [`CompensationReport::paths`]: offset by kerf (`points` ... set), by the
/// controller (`in_control`), or not at all (`reason`).
#[derive(Debug, Clone, Serialize)]
#[non_exhaustive]
pub struct CompensationPath {
    /// The path's id.
    pub id: String,
    /// The scrap side, `left` or `right` of the path seen along the tool axis.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub side: Option<String>,
    /// How far the path moved, mm (0 where it did not).
    pub offset_mm: f64,
    /// Points of the offset path.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub points: Option<usize>,
    /// Points inserted to keep the offset's chords within the tolerance.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub inserted: Option<usize>,
    /// The largest chord error of the offset against the exact offset curve, mm.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub max_chord_error_mm: Option<f64>,
    /// Whether that error is proven for every chord (on flat contours by the tangents' cone,
    /// elsewhere by the offset direction's second-derivative bound) or measured somewhere.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub proven: Option<bool>,
    /// Outside corners swung round on an arc.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub outside_corners: Option<usize>,
    /// Inside corners cut back.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub inside_corners: Option<usize>,
    /// The most material the round beam leaves in an inside corner, mm.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub max_corner_material_mm: Option<f64>,
    /// Whether the offset path was checked not to cross itself.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub crossing_checked: Option<bool>,
    /// `Some(true)`: the controller compensates this path.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub in_control: Option<bool>,
    /// Why the path is cut on the contour.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub reason: Option<String>,
}

/// `technology`: the technology entry used.
#[derive(Debug, Clone, Serialize)]
#[non_exhaustive]
pub struct TechnologyReport {
    /// The entry's label.
    pub entry: String,
    /// Its material.
    pub material: String,
    /// Its sheet thickness, mm.
    pub thickness_mm: f64,
    /// Its assist gas.
    pub gas: Option<String>,
    /// The gas pressure, bar.
    pub gas_pressure_bar: Option<f64>,
    /// Its feed, mm/min.
    pub feed_mm_per_min: f64,
    /// Its cutting power at its feed, percent.
    pub power_percent: f64,
    /// Its focus position, mm.
    pub focus_mm: Option<f64>,
    /// Its standoff, mm.
    pub standoff_mm: Option<f64>,
    /// Its kerf width, mm.
    pub kerf_width_mm: Option<f64>,
    /// Its pierce.
    pub pierce: Option<kerf_kinematics::Pierce>,
    /// Its small-hole rule.
    pub small_hole: Option<kerf_kinematics::SmallHole>,
    /// Its corner rule.
    pub corner: Option<kerf_kinematics::CornerRule>,
    /// The power floor in force (the entry's, or its default share of the power), percent.
    pub power_min_percent: f64,
    /// The ids of the cuts the small-hole rule slowed.
    pub small_holes: Vec<String>,
    /// What is commanded and what is only stated.
    pub note: String,
}

/// `micro_joints`: bridges left uncut.
#[derive(Debug, Clone, Serialize)]
#[non_exhaustive]
pub struct MicroJointsReport {
    /// The length left uncut, mm.
    pub length_mm: f64,
    /// The cut between joints, mm.
    pub spacing_mm: f64,
    /// Per contour with joints (contours without any are not listed).
    pub paths: Vec<MicroJointPath>,
    /// The joints no place was found for, as warnings.
    pub left_out: Vec<String>,
}

/// One contour of [`MicroJointsReport::paths`].
#[derive(Debug, Clone, Serialize)]
#[non_exhaustive]
pub struct MicroJointPath {
    /// The contour's id.
    pub id: String,
    /// Its joints.
    pub joints: Vec<MicroJoint>,
}

/// One joint of a [`MicroJointPath`].
#[derive(Debug, Clone, Serialize)]
#[non_exhaustive]
pub struct MicroJoint {
    /// Where it starts along the cut from the lead-in's start, mm.
    pub start_mm: f64,
    /// Where it ends, mm.
    pub end_mm: f64,
    /// Its start, mm, in the set-up's workpiece frame.
    pub start: [f64; 3],
    /// Its end, mm, in the same frame.
    pub end: [f64; 3],
}

/// `head`: the head against the part along the cuts.
#[derive(Debug, Clone, Serialize)]
#[non_exhaustive]
pub struct HeadReport {
    /// Whether the cuts were checked (the run's `cut_clearance_mm`).
    pub checked: bool,
    /// The clearance asked for, mm.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub clearance_mm: Option<f64>,
    /// The head model checked (`kerf.machine/1`'s `head` form).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub head: Option<kerf_kinematics::Head>,
    /// `machine file` or `default laser head`.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub head_source: Option<String>,
    /// The nozzle's standoff above the surface, mm.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub standoff_mm: Option<f64>,
    /// The height of the nozzle's tip zone left out of the check, mm (`null` where no path
    /// was checked).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub tip_zone_mm: Option<Option<f64>>,
    /// Per path checked, in cutting order within each set-up (`None` without the check).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub paths: Option<Vec<HeadPath>>,
    /// What the figures mean.
    pub note: String,
}

/// One path of [`HeadReport::paths`].
#[derive(Debug, Clone, Serialize)]
#[non_exhaustive]
pub struct HeadPath {
    /// The path's id.
    pub path: String,
    /// A proven lower bound of the head-to-part distance over the cut, mm (`None`: no
    /// surface to meet).
    pub min_distance_mm: Option<f64>,
    /// The pose nearest which it was found.
    pub at_pose: usize,
    /// Stretches where a head point came within the clearance.
    pub close: Vec<HeadStretch>,
    /// Whether the check finished.
    pub proven: bool,
    /// What the tilt search did.
    pub tilted: HeadTilt,
    /// Samples checked.
    pub samples: usize,
    /// Exact distance queries made.
    pub queries: usize,
}

/// One stretch of [`HeadPath::close`].
#[derive(Debug, Clone, Serialize)]
#[non_exhaustive]
pub struct HeadStretch {
    /// Its first and last pose.
    pub poses: [usize; 2],
    /// Its length, mm.
    pub length_mm: f64,
    /// The nearest distance found there, mm.
    pub distance_mm: f64,
    /// The height above the nozzle tip of the head point that came nearest, mm.
    pub at_height_mm: f64,
    /// The surface in the way.
    pub surface: Option<String>,
}

/// [`HeadPath::tilted`]: the tilt search's rounds and what it tilted.
#[derive(Debug, Clone, Serialize)]
#[non_exhaustive]
pub struct HeadTilt {
    /// Rounds of tilting and checking.
    pub rounds: usize,
    /// Cutting points whose axis was tilted to clear.
    pub cutting_points: usize,
    /// The largest tilt, degrees.
    pub max_tilt_deg: f64,
}

/// `placement`: the part on the machine.
#[derive(Debug, Clone, Serialize)]
#[non_exhaustive]
pub struct PlacementReport {
    /// `auto` (searched) or `given`.
    pub mode: String,
    /// How `rotation_deg` turns the part.
    pub rotation_order: String,
    /// One per set-up (the part clamped anew), in the order the programs run.
    pub setups: Vec<SetupReport>,
    /// Paths solved by the search (`None` for a given placement).
    pub paths_solved: Option<usize>,
    /// Paths cut from the other side of the sheet.
    pub flipped_paths: Vec<String>,
    /// The paths turned to the other side of the sheet, or kept on the given side although
    /// the nozzle meets the part there, each with the reason (paths cut as given without a
    /// question are not listed).
    pub sides: Vec<SideReport>,
    /// What the sides mean.
    pub sides_note: String,
    /// Contours cut along their wall (`kerf run` only).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub walls: Option<Vec<WallReport>>,
    /// The margin the search kept from the linear limits, mm (auto only).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub margin_mm: Option<f64>,
    /// Searches it took (auto only).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub searches: Option<usize>,
    /// What `walls` means (`kerf run` only).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub walls_note: Option<String>,
}

/// One set-up of [`PlacementReport::setups`].
#[derive(Debug, Clone, Serialize)]
#[non_exhaustive]
pub struct SetupReport {
    /// Its paths' ids.
    pub paths: Vec<String>,
    /// The part's translation, mm.
    pub translation_mm: [f64; 3],
    /// The part's rotation (Rz Ry Rx), degrees.
    pub rotation_deg: [f64; 3],
    /// The clearance the search kept from the axis limits, mm (`None` for a given placement).
    pub clearance_mm: Option<f64>,
}

/// One path of [`PlacementReport::sides`].
#[derive(Debug, Clone, Serialize)]
#[non_exhaustive]
pub struct SideReport {
    /// The path's id.
    pub id: String,
    /// `given` (the tool axis is the surface's normal) or `other`.
    pub side: String,
    /// Why it is cut from that side, in words (how many of the nozzle line's points meet the
    /// part from each side, or the reach).
    pub reason: String,
}

/// One contour of [`PlacementReport::walls`].
#[derive(Debug, Clone, Serialize)]
#[non_exhaustive]
pub struct WallReport {
    /// The contour's id.
    pub id: String,
    /// The wall's width across the contour, mm.
    pub width_mm: f64,
    /// The scrap side.
    pub scrap: String,
    /// Why the contour is taken for a wall's.
    pub reason: String,
}

/// `process`: the cuts and their order.
#[derive(Debug, Clone, Serialize)]
#[non_exhaustive]
pub struct ProcessReport {
    /// Pierces (one per cut).
    pub pierces: usize,
    /// The ids in cutting order.
    pub order: Vec<String>,
    /// Holes cut before the outlines around them.
    pub holes_cut_first: Vec<String>,
    /// Length of the contours cut, mm.
    pub cut_length_mm: f64,
    /// Length of the lead-ins and lead-outs, mm.
    pub lead_length_mm: f64,
    /// Straight distance from each cut's exit to the next pierce, mm.
    pub traverse_mm: f64,
    /// The same in the file's order, mm.
    pub file_order_traverse_mm: f64,
    /// What the order saved, mm.
    pub traverse_saved_mm: f64,
    /// Lead-ins shortened to fit, with the scale kept.
    pub lead_ins_shortened: Vec<ShortenedLead>,
    /// Cuts pierced on the contour (no room for a lead-in).
    pub pierce_on_contour: Vec<String>,
    /// What the traverse figures measure.
    pub traverse_note: String,
}

/// One lead-in of [`ProcessReport::lead_ins_shortened`].
#[derive(Debug, Clone, Serialize)]
#[non_exhaustive]
pub struct ShortenedLead {
    /// The cut's id.
    pub id: String,
    /// Its length as a share of the planned one.
    pub scale: f64,
}

/// `traverses`: the moves between cuts against the part.
#[derive(Debug, Clone, Serialize)]
#[non_exhaustive]
pub struct TraversesReport {
    /// Whether they were checked (a clearance above 0).
    pub checked: bool,
    /// The clearance kept from the part, mm.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub clearance_mm: Option<f64>,
    /// The retract along the tool axis, mm.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub retract_mm: Option<f64>,
    /// The nozzle's length along the axis that is checked, mm.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub nozzle_mm: Option<f64>,
    /// Traverses in all.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub count: Option<usize>,
    /// Traverses on a checked route.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub checked_count: Option<usize>,
    /// Those no route cleared (unchecked retract, straight move, approach).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub unchecked: Option<Vec<UncheckedTraverse>>,
    /// Routes that are not straight.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub lifted: Option<usize>,
    /// Traverses by route (`straight`, `lifted`, `safe plane`, `searched`).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub routes: Option<BTreeMap<String, usize>>,
    /// The gaps a search around the part cleared.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub searched: Option<Vec<SearchedTraverse>>,
    /// Moves split so that the tip follows the checked line.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub split_moves: Option<usize>,
    /// Length of the checked traverses, mm.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub length_mm: Option<f64>,
    /// The least distance proven on them, mm (`null`: infinite).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub min_distance_mm: Option<f64>,
    /// With the head check (`cut_clearance_mm`): the clearance the head model keeps along
    /// every checked traverse, mm.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub head_clearance_mm: Option<f64>,
    /// With the head check: the least distance proven between the head model and the part
    /// over the checked traverses, mm (`null`: infinite).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub head_min_distance_mm: Option<f64>,
    /// With the head check: traverses on which the head cleared no route, taken on the
    /// nozzle line's check with a warning (head collisions accepted).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub head_too_close: Option<usize>,
    /// What the head check of the traverses covers.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub head_note: Option<String>,
    /// Surfaces left out where a cut ends or starts.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub surfaces_in_the_cuts_way: Option<Vec<String>>,
    /// What that means.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub surfaces_note: Option<String>,
    /// Gaps where a cut's own surface comes back over the head line.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub own_surface_over_the_head: Option<Vec<OwnSurfaces>>,
    /// What `unchecked` means.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub unchecked_note: Option<String>,
    /// What `searched` means.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub searched_note: Option<String>,
    /// Why nothing was checked.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub note: Option<String>,
}

/// One gap of [`TraversesReport::unchecked`].
#[derive(Debug, Clone, Serialize)]
#[non_exhaustive]
pub struct UncheckedTraverse {
    /// The path before the gap.
    pub after: String,
    /// The path after it.
    pub before: String,
    /// Why no route cleared.
    pub reason: String,
    /// The surfaces the last routes were checked without.
    pub surfaces_left_out: Vec<String>,
}

/// One gap of [`TraversesReport::own_surface_over_the_head`].
#[derive(Debug, Clone, Serialize)]
#[non_exhaustive]
pub struct OwnSurfaces {
    /// The path before the gap.
    pub after: String,
    /// The path after it.
    pub before: String,
    /// The cut's own surfaces over the head line there.
    pub surfaces: Vec<String>,
}

/// One gap of [`TraversesReport::searched`].
#[derive(Debug, Clone, Serialize)]
#[non_exhaustive]
pub struct SearchedTraverse {
    /// The path before the gap.
    pub after: String,
    /// The path after it.
    pub before: String,
    /// Waypoints of the route found.
    pub waypoints: usize,
    /// Its length, mm.
    pub length_mm: f64,
    /// The surfaces it was checked without.
    pub surfaces_left_out: Vec<String>,
}

/// `interpolation`: the planned motion.
#[derive(Debug, Clone, Serialize)]
#[non_exhaustive]
pub struct InterpolationReport {
    /// The feed asked for, mm/min.
    pub feed_mm_per_min: f64,
    /// The interpolation cycle, s.
    pub cycle_s: f64,
    /// A proven bound of the set-points' spline from the blocks, mm.
    pub spline_deviation_bound_mm: f64,
    /// The set-points' own budget, mm (the blocks' chord and fit terms, the spline, the
    /// interpolation chord, the blend).
    pub setpoints_budget_mm: f64,
    /// Line blocks.
    pub lines: usize,
    /// Arc blocks.
    pub arcs: usize,
    /// Turns in place (the tool axis turning with the tip still).
    pub turns: usize,
    /// Interpolation cycles.
    pub cycles: usize,
    /// The program's planned duration, s.
    pub duration_s: f64,
    /// The share of the cutting time at the full feed.
    pub time_share_at_feed: f64,
    /// Per path of every set-up, in cutting order.
    pub paths: Vec<PathMotion>,
}

/// One path of [`InterpolationReport::paths`] ([`crate::path_report`]).
#[derive(Debug, Clone, Serialize)]
#[non_exhaustive]
pub struct PathMotion {
    /// The path's id.
    pub id: String,
    /// Its planned time, leads and rapids before it included, s.
    pub duration_s: f64,
    /// Its time with the beam on, s.
    pub cutting_time_s: f64,
    /// Its length with the beam on, mm.
    pub cutting_length_mm: f64,
    /// The share of its cutting time at the full feed.
    pub time_share_at_feed: f64,
    /// The share of its cutting length at the full feed.
    pub length_share_at_feed: f64,
}

/// The program's tolerance budget as its header states it (a `fit` term where arcs and merged
/// lines are written) and its `total`.
pub(crate) fn budget(gopts: &GcodeOptions) -> BTreeMap<String, Option<f64>> {
    let mut budget: BTreeMap<String, Option<f64>> = gopts
        .budget()
        .into_iter()
        .map(|(k, v)| (k.to_string(), v))
        .collect();
    budget.insert("total".into(), Some(gopts.budget_total()));
    budget
}

impl ProgramReport {
    /// The programs of `motions` (one per set-up, written into `files`) in `dialect` with the
    /// resolved process codes.
    pub(crate) fn of(
        dialect: Dialect,
        process: &ProcessCodes,
        motions: &[Motion],
        files: Vec<String>,
    ) -> Self {
        Self {
            dialect: dialect.name().to_string(),
            beam_on: process.beam_on.clone(),
            beam_off: process.beam_off.clone(),
            pierce_dwell_s: process.pierce_dwell_s,
            pierce_standoff_mm: process.pierce_standoff,
            // A cut: a stretch of cutting blocks of one path after a rapid (or at the start).
            cuts: motions
                .iter()
                .map(|m| {
                    let b = m.blocks();
                    (0..b.len())
                        .filter(|&i| kerf_interp::starts_cut(b, i))
                        .count()
                })
                .sum(),
            files,
        }
    }
}

impl DiscretizeReport {
    /// The figures of the discretizations `discs` of `file`'s curves (at `tolerance_mm`) and
    /// their toolpath.
    pub(crate) fn of(
        file: &CurvesFile,
        discs: &[Discretization],
        tp: &ToolpathFile,
        tolerance_mm: f64,
    ) -> Self {
        Self {
            curves: file.curves.len(),
            segments: discs.iter().map(Discretization::segments).sum(),
            // From the curvature the walk evaluated at its points.
            n_star: discs.iter().map(|d| d.n_star(tolerance_mm)).sum(),
            max_chord_error: tp
                .paths
                .iter()
                .map(|p| p.max_chord_error)
                .fold(0.0, f64::max),
            c0_breaks: discs.iter().map(|d| d.c0_breaks().len()).sum(),
        }
    }
}

impl NormalsReport {
    /// The figures of the oriented points of `file`'s curves.
    pub(crate) fn of(file: &CurvesFile, oriented: &[Oriented]) -> Self {
        Self {
            points: oriented.iter().map(|o| o.points().len()).sum(),
            inserted: oriented.iter().map(|o| o.inserted).sum(),
            max_surface_distance: oriented
                .iter()
                .map(|o| o.max_surface_distance)
                .fold(0.0, f64::max),
            jumps: oriented.iter().map(|o| o.jumps.len()).sum(),
            curves_without_surface: file.curves.iter().filter(|c| c.surface.is_none()).count(),
        }
    }
}

impl KinematicsReport {
    /// The figures of the solved paths, with what the tilt tolerance did.
    pub(crate) fn of(solved: &[SolvedPath], tilt: Option<TiltTotals>) -> Self {
        Self {
            poses: solved.iter().map(|s| s.poses.len()).sum(),
            inserted: solved.iter().map(|s| s.inserted).sum(),
            max_rotary_step_between_cutting_points: solved
                .iter()
                .map(|s| s.max_rotary_step_between_cutting_points)
                .fold(0.0, f64::max),
            max_linearization_error: solved
                .iter()
                .map(|s| s.max_linearization_error)
                .fold(0.0, f64::max),
            pole_points: solved.iter().map(|s| s.pole_points).sum(),
            pole_tip_error: solved.iter().map(|s| s.pole_tip_error).fold(0.0, f64::max),
            tilt,
        }
    }
}

impl InterpolationReport {
    /// The figures of the planned `motions` (one per set-up, `setup_ids[k]` naming the paths
    /// of the k-th) at `feed_mm_per_min` and `cycle_s`, written with `gopts`.
    pub(crate) fn of(
        motions: &[Motion],
        setup_ids: &[Vec<String>],
        feed_mm_per_min: f64,
        cycle_s: f64,
        gopts: &GcodeOptions,
    ) -> Self {
        let (mut lines, mut arcs, mut turns) = (0, 0, 0);
        for m in motions {
            let c = m.counts();
            lines += c.lines;
            arcs += c.arcs;
            turns += c.turns;
        }
        let duration: f64 = motions.iter().map(Motion::duration).sum();
        // The set-points follow a smooth spline through the blocks' nodes: a proven bound of
        // its distance from the blocks, and the set-points' own budget (the blocks' chord and
        // fit terms, the spline, the interpolation chord, the blend; the linearization does
        // not apply: the set-points put the tip on the path).
        let spline_bound = motions
            .iter()
            .map(Motion::spline_deviation_bound)
            .fold(0.0, f64::max);
        let setpoints_budget = gopts
            .budget()
            .into_iter()
            .filter(|(k, _)| *k != "linearization")
            .filter_map(|(_, v)| v)
            .sum::<f64>()
            + spline_bound;
        Self {
            feed_mm_per_min,
            cycle_s,
            spline_deviation_bound_mm: spline_bound,
            setpoints_budget_mm: setpoints_budget,
            lines,
            arcs,
            turns,
            cycles: motions.iter().map(Motion::cycles).sum(),
            duration_s: duration,
            time_share_at_feed: if duration > 0.0 {
                motions
                    .iter()
                    .map(|m| m.time_share_at_feed() * m.duration())
                    .sum::<f64>()
                    / duration
            } else {
                0.0
            },
            paths: motions
                .iter()
                .zip(setup_ids)
                .flat_map(|(m, ids)| path_report(m, ids))
                .collect(),
        }
    }
}

/// The planned time of every path and the share at the programmed feed, for the summaries
/// (`ids[k]` names the motion's path `k`; `path k` where it has none).
pub fn path_report(motion: &Motion, ids: &[String]) -> Vec<PathMotion> {
    let share = |part: f64, whole: f64| if whole > 0.0 { part / whole } else { 0.0 };
    motion
        .path_stats()
        .iter()
        .map(|p| PathMotion {
            id: ids
                .get(p.path)
                .cloned()
                .unwrap_or_else(|| format!("path {}", p.path)),
            duration_s: p.duration,
            cutting_time_s: p.cutting_time,
            cutting_length_mm: p.cutting_length,
            time_share_at_feed: share(p.time_at_feed, p.cutting_time),
            length_share_at_feed: share(p.length_at_feed, p.cutting_length),
        })
        .collect()
}
