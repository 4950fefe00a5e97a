//! LinuxCNC with its own tool-tip kinematics ([`Dialect::LinuxcncTcp`](super::Dialect)): which
//! kinematics module computes a kerf machine, with which HAL parameters, and the split of
//! rapids so that the tip-space `G0` follows kerf's joint-space traverse.
//!
//! LinuxCNC 2.9's `xyzac-trt-kins` (`src/emc/kinematics/trtfuncs.c`) computes, with
//! `r` its `{x,y,z}-rot-point`, `d = (0, y-offset, z-offset + tool-offset)` and the joints `J`,
//!
//! ```text
//! world = r + Rz(-C) [ Rx(-A) (J - r - d) + d ]
//! ```
//!
//! which is kerf's `table-table` (`P = q_c + Rz(sC)^T [(q_a - q_c) + Rx(sA)^T (T - q_a)]`) with
//! `s = +1` (`conventional: false`), `q_c = r`, `q_a - q_c = d` and `tool_offset` 0 (kerf's tip
//! is `tool_offset` below the joints without adding it back; LinuxCNC folds the tool length into
//! `d` and applies its length offset itself).
//!
//! Its `5axiskins` (a B/C head, `src/emc/kinematics/5axiskins.c`) computes, with `L` its
//! `pivot-length` pin and the W joint at 0,
//!
//! ```text
//! world = J + (0, 0, L) + L (sin B cos C, sin B sin C, -cos B)
//! ```
//!
//! which is kerf's `fork-head` (`P = XYZ + Rz(C) (d + Ry(s B) (tx, ty, -L))`) with tilt B,
//! `tilt_sign` -1, `d = (0, 0, L)` and no lateral offset: `Rz(C) ((0, 0, L) + Ry(-B) (0, 0,
//! -L)) = (0, 0, L) + L (sin B cos C, sin B sin C, -cos B)`, and the tool axis `Rz(C) Ry(-B) ez`
//! is the direction from LinuxCNC's tip to its pivot. Those are the machines this dialect
//! writes for; any other is refused by name ([`linuxcnc_kinematics`]).

use kerf_kinematics::{Machine, Parameter};

use crate::error::{InterpError, Result};
use crate::model::AxisModel;

/// How far (mm) the tip of a `linuxcnc-tcp` rapid may run from kerf's joint-space traverse at
/// the middle of each `G0`: LinuxCNC moves the tip on a straight line between the `G0` ends
/// (with the rotary axes linear, as in joint space), so a traverse is split until each
/// piece's tip chord is this close to the joint-space path at its middle. For fixed rotary axes
/// the head is rigid with the tip, so the whole head runs within it of the checked traverse
/// (to second order between the middles).
pub const RAPID_TCP_TOLERANCE_MM: f64 = 0.1;

/// The most pieces a rapid is split into (a bound that rounding cannot defeat: the split
/// doubles from one piece and stops here).
pub const RAPID_TCP_MAX_PIECES: usize = 256;

/// A LinuxCNC kinematics module that computes a kerf machine: its name and the HAL pins a
/// configuration sets (`setp <module>.<pin> <value>`).
#[derive(Debug, Clone, PartialEq)]
#[non_exhaustive]
pub struct LinuxcncKinematics {
    /// The module (`loadrt <module>`, `[KINS] KINEMATICS`).
    pub module: &'static str,
    /// The `[TRAJ] COORDINATES` the module needs, in joint order.
    pub coordinates: &'static str,
    /// The HAL input pins and their values (mm), in the module's order.
    pub pins: Vec<(&'static str, f64)>,
}

impl LinuxcncKinematics {
    /// The HAL lines that set the module's parameters.
    pub fn setp_lines(&self) -> Vec<String> {
        self.pins
            .iter()
            .map(|(pin, v)| format!("setp {}.{pin} {v}", self.module))
            .collect()
    }
}

/// The LinuxCNC kinematics module that computes `machine` exactly, for a tool-tip program.
///
/// Supported (module docs): `table-table` with `conventional: false` and `tool_offset` 0
/// (LinuxCNC 2.9's `xyzac-trt-kins`), and `fork-head` with tilt B, `tilt_sign` -1, `d = (0, 0,
/// L)` and no lateral offset (`5axiskins`, coordinates `XYZBCW`, the W joint left at 0). Other
/// machines have no module in LinuxCNC 2.9 that computes them as kerf does, so a tool-tip
/// program would put the tip elsewhere: refused.
///
/// # Errors
/// [`InterpError::DialectMachine`] naming what does not match.
pub fn linuxcnc_kinematics(machine: &Machine) -> Result<LinuxcncKinematics> {
    let refuse = |reason: String| {
        Err(InterpError::DialectMachine {
            dialect: "linuxcnc-tcp",
            reason,
        })
    };
    let k = &machine.kinematics;
    let params = k.parameters();
    let get = |name: &str| params.iter().find(|(n, _)| *n == name).map(|(_, v)| v);
    let number = |name: &str| match get(name) {
        Some(Parameter::Number(v)) => Some(*v),
        _ => None,
    };
    let numbers = |name: &str| match get(name) {
        Some(Parameter::Numbers(v)) => v.clone(),
        _ => Vec::new(),
    };
    match k.type_name() {
        "table-table" => {}
        "fork-head" => {
            let l = number("L").unwrap_or(f64::NAN);
            let d = numbers("d");
            let lateral = numbers("tool_lateral");
            let why = if k.tilt_name() != "B" {
                "the tilt is A (5axiskins tilts B)".to_string()
            } else if number("tilt_sign") != Some(-1.0) {
                "kinematics.tilt_sign is +1: 5axiskins turns B the other way (tilt_sign -1 computes it)".to_string()
            } else if d != [0.0, 0.0, l] {
                format!("kinematics.d is {d:?}: 5axiskins puts its pivot L = {l} mm above the joints' point, d = [0, 0, {l}]")
            } else if lateral.iter().any(|v| *v != 0.0) {
                format!("kinematics.tool_lateral is {lateral:?}: 5axiskins has the tip on the tool axis, [0, 0]")
            } else {
                return Ok(LinuxcncKinematics {
                    module: "5axiskins",
                    coordinates: "XYZBCW",
                    pins: vec![("pivot-length", l)],
                });
            };
            return refuse(format!("fork-head for LinuxCNC's 5axiskins: {why}"));
        }
        other => {
            return refuse(format!(
                "the machine's kinematics are {other}; LinuxCNC's tool-tip kinematics that kerf writes for are xyzac-trt-kins (a table-table) and 5axiskins (a B/C fork head); use the linuxcnc dialect, joint space, for the others"
            ))
        }
    }
    if let Some(Parameter::Flag(true)) = get("conventional") {
        return refuse(
            "kinematics.conventional is true: LinuxCNC 2.9's xyzac-trt-kins turns A and C the other way (conventional: false computes it)".to_string(),
        );
    }
    let tool = number("tool_offset").unwrap_or(f64::NAN);
    if tool != 0.0 {
        return refuse(format!(
            "kinematics.tool_offset is {tool}: xyzac-trt-kins adds the tool length back at the pivot and LinuxCNC applies its own length offset; give the tool length to the controller (G43) and 0 here"
        ));
    }
    let (Some(Parameter::Numbers(rot)), Some(y), Some(z)) =
        (get("rot_point"), number("y_offset"), number("z_offset"))
    else {
        return refuse(
            "the table-table parameters rot_point, y_offset, z_offset are missing".to_string(),
        );
    };
    let [rx, ry, rz] = [0, 1, 2].map(|i| rot.get(i).copied().unwrap_or(f64::NAN));
    Ok(LinuxcncKinematics {
        module: "xyzac-trt-kins",
        coordinates: "XYZAC",
        pins: vec![
            ("x-rot-point", rx),
            ("y-rot-point", ry),
            ("z-rot-point", rz),
            ("x-offset", 0.0),
            ("y-offset", y),
            ("z-offset", z),
            ("tool-offset", 0.0),
        ],
    })
}

/// The ends of the `G0` pieces of a rapid from the axes `from` to `to` (the last is `to`):
/// `2^k` equal pieces in joint space, the fewest (at most [`RAPID_TCP_MAX_PIECES`]) whose tip
/// chords lie within [`RAPID_TCP_TOLERANCE_MM`] of the joint-space path's tip at each piece's
/// middle.
pub(super) fn rapid_pieces<M: AxisModel + ?Sized>(
    model: &M,
    from: &[f64; 5],
    to: &[f64; 5],
) -> Vec<[f64; 5]> {
    let at = |f: f64| -> [f64; 5] { std::array::from_fn(|k| from[k] + f * (to[k] - from[k])) };
    let mut n = 1;
    loop {
        let within = (0..n).all(|i| {
            let (a, b) = (i as f64 / n as f64, (i + 1) as f64 / n as f64);
            let (ta, tb) = (model.tip(&at(a)), model.tip(&at(b)));
            let mid = model.tip(&at((a + b) / 2.0));
            (nalgebra::center(&ta, &tb) - mid).norm() <= RAPID_TCP_TOLERANCE_MM
        });
        if within || n >= RAPID_TCP_MAX_PIECES {
            break;
        }
        n *= 2;
    }
    (1..=n)
        .map(|i| if i == n { *to } else { at(i as f64 / n as f64) })
        .collect()
}
