//! Where the part goes on the machine ([`PlaceMode`]; `--place` of `kerf run` and `kerf post`).
//!
//! [`PlaceMode::Fixed`] (`--place X,Y,Z[,RX,RY,RZ]`) applies a fixed part-to-workpiece
//! transform (mm, degrees, `Rz Ry Rx`); [`PlaceMode::Auto`] (`--place auto`) asks [`kerf_kinematics::auto_place`] for one that puts every pose
//! within the axis limits (turning contours whose side the head cannot reach, and rotating the
//! part by quarter turns if it does not fit as modelled). The toolpath stays in part
//! coordinates; the axes file, the program and the report are in workpiece coordinates, and
//! the report says which placement was used.

use kerf_kinematics::{auto_setups, AutoPlaceOptions, Machine, Placement, Pose, Setup, SetupPlan};

use crate::error::{kin, Error};
use crate::report::{PlacementReport, SetupReport, SideReport};

/// The clearance `kerf post --place auto` keeps from the linear limits, mm: room for the
/// default 10 mm retract of `kerf gcode` plus 1 mm.
pub const AUTO_CLEARANCE_MM: f64 = 11.0;

/// Where the part goes on the machine.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
#[non_exhaustive]
pub enum PlaceMode {
    /// Where the CAD model put it (the identity placement).
    #[default]
    AsModelled,
    /// This placement.
    Fixed(Placement),
    /// Search for a placement that puts every pose within the axis limits, the motion centred
    /// in the travel, contours turned to the side the head can reach, the part turned by
    /// quarter turns if it does not fit as modelled, and several set-ups if one does not fit.
    Auto,
}

impl PlaceMode {
    /// Reads `auto` or `X,Y,Z[,RX,RY,RZ]` (mm, degrees; `p' = Rz Ry Rx p + t`).
    ///
    /// # Errors
    /// [`kerf_kinematics::PlacementParseError`] naming what is wrong with the text.
    pub fn parse(text: &str) -> Result<PlaceMode, kerf_kinematics::PlacementParseError> {
        if text.trim().eq_ignore_ascii_case("auto") {
            Ok(PlaceMode::Auto)
        } else {
            Placement::parse(text).map(PlaceMode::Fixed)
        }
    }
}

/// The placement used, with what [`PlaceMode::Auto`] decided.
#[derive(Debug, Clone)]
pub struct Placed {
    /// The set-ups (one unless `auto` had to place parts or contours separately).
    pub plan: SetupPlan,
    /// Chosen by [`PlaceMode::Auto`].
    pub auto: bool,
    /// For each path, how its head lines meet the part from each side of the sheet
    /// ([`kerf_process::head_lines`], part coordinates, the given side being the surface's
    /// normal); empty where they were not looked at (not `auto`, or unchecked traverses).
    pub head_lines: Vec<kerf_process::HeadLines>,
}

/// Why a path is cut from the side it is, where that is not simply the given side.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum SideReason {
    /// Turned: the head cannot reach the given side within the tilt limits.
    Reach,
    /// Turned: the nozzle meets the part from the given side and not from the other.
    HeadLines,
    /// Kept: the nozzle meets the part from the given side and not from the other, but the
    /// machine cannot reach the other side.
    HeadLinesUnreachable,
    /// Kept: the nozzle meets the part from both sides.
    BothSides,
    /// Kept: the nozzle meets the part from the given side, but the contour lies on a thick
    /// sheet's face, which the beam must enter.
    Sheet,
}

impl Placed {
    /// The paths' sides by their head lines ([`kerf_process::head_lines`]): each path whose
    /// head meets the part from the given side and not from the other is turned, unless the
    /// placement turned it back because the machine cannot reach that side. `self` must have
    /// been placed with those paths already turned (see [`sides_by_head_lines`]).
    pub(crate) fn with_head_lines(mut self, head_lines: Vec<kerf_process::HeadLines>) -> Self {
        for (flip, h) in self.plan.flipped.iter_mut().zip(&head_lines) {
            if h.prefers_other_side() {
                *flip = !*flip;
            }
        }
        self.head_lines = head_lines;
        self
    }

    /// Why path `i` is cut from its side, where there is more to it than the given side.
    fn side_reason(&self, i: usize) -> Option<SideReason> {
        let flipped = self.plan.flipped.get(i).copied().unwrap_or(false);
        let h = self.head_lines.get(i).copied().unwrap_or_default();
        let prefer = h.prefers_other_side();
        match (flipped, prefer) {
            (true, true) => Some(SideReason::HeadLines),
            (true, false) => Some(SideReason::Reach),
            (false, true) => Some(SideReason::HeadLinesUnreachable),
            (false, false) if h.on_sheet && h.given > 0 => Some(SideReason::Sheet),
            (false, false) => (h.given > 0 && h.other > 0).then_some(SideReason::BothSides),
        }
    }

    /// The `sides` entries of the report: every path turned, or kept on the given side
    /// although its nozzle meets the part there, with the reason.
    fn sides_report(&self, ids: &[&str]) -> Vec<SideReport> {
        (0..ids.len())
            .filter_map(|i| {
                let why = self.side_reason(i)?;
                let h = self.head_lines.get(i).copied().unwrap_or_default();
                let (side, reason) = match why {
                    SideReason::Reach => (
                        "other",
                        "the head cannot reach the given side within the tilt limits".to_string(),
                    ),
                    SideReason::HeadLines => (
                        "other",
                        format!(
                            "the nozzle's line along the tool axis meets the part from the given side at {} of {} points (from {:.1} mm along the axis), from the other side at none",
                            h.given, h.points, h.given_from_mm
                        ),
                    ),
                    SideReason::HeadLinesUnreachable => (
                        "given",
                        format!(
                            "the nozzle's line meets the part from the given side at {} of {} points (from {:.1} mm along the axis) and not from the other, but the head cannot reach the other side",
                            h.given, h.points, h.given_from_mm
                        ),
                    ),
                    SideReason::BothSides => (
                        "given",
                        format!(
                            "the nozzle's line meets the part from both sides: the given side at {} of {} points (from {:.1} mm along the axis), the other at {} (from {:.1} mm)",
                            h.given, h.points, h.given_from_mm, h.other, h.other_from_mm
                        ),
                    ),
                    SideReason::Sheet => (
                        "given",
                        format!(
                            "the nozzle's line meets the part from the given side at {} of {} points (from {:.1} mm along the axis), but the contour lies on the face of a sheet of known thickness (sheet_thickness_mm), which the beam enters: it is never turned over",
                            h.given, h.points, h.given_from_mm
                        ),
                    ),
                };
                Some(SideReport {
                    id: ids.get(i).copied().unwrap_or("").to_string(),
                    side: side.to_string(),
                    reason,
                })
            })
            .collect()
    }

    /// The poses of every path in workpiece coordinates.
    pub fn apply(&self, poses: &[Vec<Pose>]) -> Vec<Vec<Pose>> {
        self.plan.apply(poses)
    }

    /// The poses of path `i` (any sequence of its poses) in workpiece coordinates.
    pub fn apply_one(&self, i: usize, poses: &[Pose]) -> Vec<Pose> {
        let flip = self.plan.flipped.get(i).copied().unwrap_or(false);
        kerf_kinematics::place_paths(&self.placement_of(i), &[flip], &[poses.to_vec()])
            .pop()
            .unwrap_or_default()
    }

    /// The placement of path `i`.
    pub fn placement_of(&self, i: usize) -> Placement {
        self.plan.placement_of(i)
    }

    /// True if nothing was moved or turned.
    pub fn is_identity(&self) -> bool {
        self.plan.setups.iter().all(|s| s.placement.is_identity())
            && !self.plan.flipped.contains(&true)
    }

    /// The `placement` object of `report.json` (`ids` are the paths' ids in order); the run
    /// adds the walls and the search's margin.
    pub fn report(&self, ids: &[&str]) -> PlacementReport {
        let setups = self
            .plan
            .setups
            .iter()
            .map(|s| {
                let t = s.placement.translation_mm;
                SetupReport {
                    paths: s
                        .paths
                        .iter()
                        .map(|&i| ids.get(i).copied().unwrap_or("").to_string())
                        .collect(),
                    translation_mm: [t.x, t.y, t.z],
                    rotation_deg: s.placement.rotation_deg,
                    clearance_mm: self.auto.then_some(s.clearance_mm),
                }
            })
            .collect();
        PlacementReport {
            mode: if self.auto { "auto" } else { "given" }.into(),
            rotation_order: "Rz Ry Rx (about fixed workpiece axes, x first); p' = R p + t".into(),
            setups,
            paths_solved: self.auto.then_some(self.plan.paths_solved),
            flipped_paths: ids
                .iter()
                .zip(&self.plan.flipped)
                .filter(|(_, f)| **f)
                .map(|(id, _)| id.to_string())
                .collect(),
            sides: self.sides_report(ids),
            walls: None,
            margin_mm: None,
            searches: None,
            walls_note: None,
            sides_note: "side: given = the tool axis is the surface's normal, other = reversed (the beam comes from the other side of the sheet); with the placement auto and checked traverses a contour is turned where the nozzle's line along the tool axis (from 3/4 of the clearance to the retract plus the nozzle, at up to 64 of its points) comes within half the clearance of a surface of the file from the given side and from the other side nowhere, reach permitting; the lead-ins stay on the scrap side decided with the given normal".into(),
        }
    }

    /// One line for the summary.
    pub fn summary(&self) -> String {
        let flips = self.plan.flipped.iter().filter(|f| **f).count();
        let for_head = (0..self.plan.flipped.len())
            .filter(|&i| self.side_reason(i) == Some(SideReason::HeadLines))
            .count();
        let flips = match (flips, for_head) {
            (0, _) => String::new(),
            (n, 0) => format!(", {n} contours cut from the other side of the sheet"),
            (n, k) => format!(
                ", {n} contours cut from the other side of the sheet ({k} of them because the nozzle meets the part from the given side)"
            ),
        };
        match self.plan.setups.as_slice() {
            [one] => format!(
                "placed {}: {}{flips}",
                if self.auto { "automatically" } else { "as given" },
                one.placement
            ),
            many => format!(
                "placed automatically in {} set-ups (the part does not fit the machine in one; see placement in report.json){flips}",
                many.len()
            ),
        }
    }
}

/// The placement of the paths `ids` with `poses` for `mode`. [`PlaceMode::Auto`] searches
/// with `auto`: its margin keeps the retract between contours (which moves the head along
/// the tool axis) inside every linear limit, and its `flip` must be false for a thick sheet's
/// contours (turned over, the nozzle would stand off from the far face); `file` is named in
/// errors.
///
/// # Errors
/// [`Error::Kinematics`] when `auto` finds nothing that fits (the message names the axis and
/// how much travel is missing).
pub fn place(
    machine: &Machine,
    ids: &[&str],
    poses: &[Vec<Pose>],
    mode: PlaceMode,
    auto: &AutoPlaceOptions,
    file: Option<&std::path::Path>,
) -> Result<Placed, Error> {
    let single = |placement: Placement| Placed {
        plan: SetupPlan {
            setups: vec![Setup {
                paths: (0..poses.len()).collect(),
                placement,
                clearance_mm: f64::NAN,
            }],
            flipped: vec![false; poses.len()],
            rotations_tried: 0,
            paths_solved: 0,
        },
        auto: false,
        head_lines: Vec::new(),
    };
    match mode {
        PlaceMode::AsModelled => Ok(single(Placement::IDENTITY)),
        PlaceMode::Fixed(p) => Ok(single(p)),
        PlaceMode::Auto => {
            let refs: Vec<(&str, &[Pose])> = ids
                .iter()
                .copied()
                .zip(poses.iter().map(Vec::as_slice))
                .collect();
            let plan = auto_setups(machine, &refs, auto).map_err(kin(file))?;
            Ok(Placed {
                plan,
                auto: true,
                head_lines: Vec::new(),
            })
        }
    }
}

/// How the head lines of every path (`poses`, part coordinates, the surfaces' normals) meet
/// the part, the file's surfaces all in their places ([`kerf_process::head_lines`]), and the
/// paths' poses with the tool axes of those better cut from the other side already turned:
/// what [`place`] is then given, so that the placement checks the machine's reach on the
/// chosen side (and turns a path back where only the given side is reachable);
/// [`Placed::with_head_lines`] then records the choice.
///
/// # Errors
/// [`Error::Process`] for a surface that cannot be used for the distance queries.
pub(crate) fn sides_by_head_lines(
    file: &kerf_format::CurvesFile,
    poses: &[Vec<Pose>],
    opts: &kerf_process::TraverseOptions,
    source: Option<&std::path::Path>,
) -> Result<(Vec<kerf_process::HeadLines>, Vec<Vec<Pose>>), Error> {
    let all: Vec<usize> = (0..file.curves.len()).collect();
    let obs = kerf_process::Obstacles::from_file(file, &all, |p| *p).map_err(|source_err| {
        Error::Process {
            file: source.map(std::path::Path::to_path_buf),
            source: source_err,
        }
    })?;
    let heads: Vec<kerf_process::HeadLines> = {
        use rayon::prelude::*;
        poses
            .par_iter()
            .map(|p| kerf_process::head_lines(&obs, p, opts))
            .collect()
    };
    // A thick sheet's contour stays on its side (the import put it on the side that faces
    // up; turned over, the nozzle would stand off from the far face, inside the sheet).
    let heads: Vec<kerf_process::HeadLines> = heads
        .into_iter()
        .zip(&file.curves)
        .map(|(h, c)| match c.sheet_thickness_mm {
            Some(_) => h.kept_on_sheet(),
            None => h,
        })
        .collect();
    let turned = poses
        .iter()
        .zip(&heads)
        .map(|(p, h)| {
            if h.prefers_other_side() {
                p.iter()
                    .map(|q| Pose {
                        position: q.position,
                        axis: -q.axis,
                    })
                    .collect()
            } else {
                p.clone()
            }
        })
        .collect();
    Ok((heads, turned))
}
