//! Where the part goes on the machine ([`PlaceMode`]; `--place` of `kerf run` and `kerf post`).
//!
//! [`PlaceMode::Fixed`] (`--place X,Y,Z[,RX,RY,RZ]`) applies a fixed part-to-workpiece
//! transform (mm, degrees, `Rz Ry Rx`); [`PlaceMode::Auto`] (`--place auto`) asks [`kerf_kinematics::auto_place`] for one that puts every pose
//! within the axis limits (turning contours whose side the head cannot reach, and rotating the
//! part by quarter turns if it does not fit as modelled). The toolpath stays in part
//! coordinates; the axes file, the program and the report are in workpiece coordinates, and
//! the report says which placement was used.

use kerf_kinematics::{
    auto_setups, AutoPlaceOptions, Machine, PathOptions, Placement, Pose, Setup, SetupPlan,
};
use serde_json::{json, Value};

use crate::error::{kin, Error};

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
    /// A message saying what is wrong with the text.
    pub fn parse(text: &str) -> Result<PlaceMode, String> {
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
}

impl Placed {
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

    /// The `placement` object of `report.json`.
    pub fn json(&self, ids: &[&str]) -> Value {
        let setups: Vec<Value> = self
            .plan
            .setups
            .iter()
            .map(|s| {
                let t = s.placement.translation_mm;
                json!({
                    "paths": s.paths.iter().map(|&i| ids.get(i).copied().unwrap_or("")).collect::<Vec<_>>(),
                    "translation_mm": [t.x, t.y, t.z],
                    "rotation_deg": s.placement.rotation_deg,
                    "clearance_mm": if self.auto { Some(s.clearance_mm) } else { None },
                })
            })
            .collect();
        json!({
            "mode": if self.auto { "auto" } else { "given" },
            "rotation_order": "Rz Ry Rx (about fixed workpiece axes, x first); p' = R p + t",
            "setups": setups,
            "flipped_paths": ids.iter().zip(&self.plan.flipped).filter(|(_, f)| **f).map(|(id, _)| *id).collect::<Vec<_>>(),
        })
    }

    /// One line for the summary.
    pub fn summary(&self) -> String {
        let flips = self.plan.flipped.iter().filter(|f| **f).count();
        let flips = if flips > 0 {
            format!(", {flips} contours cut from the other side of the sheet")
        } else {
            String::new()
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

/// The placement of the paths `ids` with `poses` for `mode`. [`PlaceMode::Auto`] keeps
/// `clearance_mm` from every linear limit (the retract between contours moves the head that
/// far along the tool axis); `file` is named in errors.
///
/// # Errors
/// [`Error::Kinematics`] when `auto` finds nothing that fits (the message names the axis and
/// how much travel is missing).
pub fn place(
    machine: &Machine,
    ids: &[&str],
    poses: &[Vec<Pose>],
    mode: PlaceMode,
    path_options: &PathOptions,
    clearance_mm: f64,
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
        },
        auto: false,
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
            let plan = auto_setups(
                machine,
                &refs,
                &AutoPlaceOptions::default()
                    .with_path_options(*path_options)
                    .with_margin_mm(clearance_mm),
            )
            .map_err(kin(file))?;
            Ok(Placed { plan, auto: true })
        }
    }
}
