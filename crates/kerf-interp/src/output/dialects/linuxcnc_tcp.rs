//! `linuxcnc-tcp`: LinuxCNC with its own tool-tip kinematics: the tip `X Y Z` in the
//! workpiece frame and the rotary axes, `G94` with `F` the tip's mean planned speed of the
//! block (deg/min of the rotary motion where the tip stands), `G64 P<q> Q0` on cuts and `G61`
//! on rapids, each rapid split so that its tip follows kerf's joint-space traverse within
//! [`RAPID_TCP_TOLERANCE_MM`](crate::RAPID_TCP_TOLERANCE_MM); comments, beam, power, micro-joints and footer as `linuxcnc`
//! (no controller kerf compensation). Below: which kinematics module computes a kerf machine,
//! with which HAL parameters.
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

use kerf_kinematics::Axes;
use kerf_kinematics::{Machine, Parameter};
use nalgebra::{Point3, Vector3};

use super::super::writer::Rules;
use super::super::writer::{feed_number, rs274_feed, Writer};
use super::super::{LaserPower, ProcessCodes};
use super::Linuxcnc;
use crate::block::Block;
use crate::error::{InterpError, Result};
use crate::model::AxisModel;

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
            "kinematics.tool_offset is {tool}: xyzac-trt-kins adds the tool length back at the pivot, which kerf's table-table does not; kerf's programs cancel the controller's length offset (G49), so the focus must be the machine's reference: tool_offset 0"
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

/// LinuxCNC with its own tool-tip kinematics.
pub(in crate::output) struct LinuxcncTcp;

impl Rules for LinuxcncTcp {
    fn name(&self) -> &'static str {
        "linuxcnc-tcp"
    }

    fn beam_codes(&self) -> (&'static str, &'static str) {
        Linuxcnc.beam_codes()
    }

    fn comment(&self, text: &str) -> String {
        Linuxcnc.comment(text)
    }

    fn machine_lines(&self, model: &dyn AxisModel) -> Result<Vec<String>> {
        let machine = model.machine().ok_or_else(|| InterpError::DialectMachine {
            dialect: "linuxcnc-tcp",
            reason:
                "the program needs a kerf.machine/1 machine to name LinuxCNC's kinematics module"
                    .to_string(),
        })?;
        let k = linuxcnc_kinematics(machine)?;
        let mut lines = vec![format!(
            "kinematics: LinuxCNC [KINS] KINEMATICS = {}, [TRAJ] COORDINATES = {}, its tool-tip kinematics active [switchkins type 0]",
            k.module, k.coordinates
        )];
        lines.extend(
            k.setp_lines()
                .into_iter()
                .map(|l| format!("kinematics: {l}")),
        );
        Ok(lines)
    }

    fn describe(&self, n: [&str; 5]) -> (String, String, &'static str) {
        (
            format!(
                "kerf LinuxCNC tool-tip program: X Y Z the tool tip in the workpiece frame, {} {} the rotary axes",
                n[3], n[4]
            ),
            format!(
                "feed: G94, F in mm/min of the tool tip [the kinematics' world X Y Z], the block's mean planned speed;\nfeed: on blocks where the tip stands F is deg/min of the rotary motion;\nfeed: rapids G0 in exact path G61, split so that the tip follows kerf's joint-space traverse within {} mm",
                crate::RAPID_TCP_TOLERANCE_MM
            ),
            "arcs written as G1 chords",
        )
    }

    fn preamble(&self, w: &mut Writer<'_>) {
        w.line("G17 G21 G40 G49 G54 G80 G90 G94");
        w.line("G61");
    }

    fn power_header(&self, w: &mut Writer<'_>) {
        Linuxcnc.power_header(w);
    }

    fn rapid(&self, w: &mut Writer<'_>, p: Point3<f64>, q: Axes, _u: Vector3<f64>) {
        w.tip_rapid("G0", p, q, |w, tip, a| tcp_words(w, tip, a[3], a[4]));
    }

    fn pierce_beam_on(&self, line: String) -> String {
        Linuxcnc.pierce_beam_on(line)
    }

    fn blend_on(&self, w: &mut Writer<'_>) {
        Linuxcnc.blend_on(w);
    }

    fn descent(
        &self,
        w: &mut Writer<'_>,
        b: &Block,
        start: Point3<f64>,
        _u: Vector3<f64>,
        t: f64,
        _h: f64,
    ) {
        tcp_move(w, start, b.start_axes, t);
    }

    fn blend_off(&self, w: &mut Writer<'_>) {
        Linuxcnc.blend_off(w);
    }

    fn cut(&self, w: &mut Writer<'_>, b: &Block, t: f64) {
        w.block_pieces(b, t, |w, s, q, dt, _| tcp_move(w, b.pose_at(s).0, q, dt));
    }

    fn pierce_power(&self, w: &mut Writer<'_>, power: &LaserPower) {
        Linuxcnc.pierce_power(w, power);
    }

    fn cut_power(&self, w: &mut Writer<'_>, power: &LaserPower) {
        Linuxcnc.cut_power(w, power);
    }

    fn power_off(&self, w: &mut Writer<'_>) {
        Linuxcnc.power_off(w);
    }

    fn joint_codes(
        &self,
        process: &ProcessCodes,
    ) -> std::result::Result<(Vec<String>, Vec<String>), &'static str> {
        Linuxcnc.joint_codes(process)
    }

    fn footer(&self, w: &mut Writer<'_>) {
        Linuxcnc.footer(w);
    }
}

/// The words of a position: the tip `X Y Z` and the rotary axes.
pub(super) fn tcp_words(w: &Writer<'_>, tip: &Point3<f64>, tilt: f64, c: f64) -> String {
    let n = &w.names;
    format!(
        "X{} Y{} Z{} {}{} {}{}",
        w.num(tip.x),
        w.num(tip.y),
        w.num(tip.z),
        n[3],
        w.num(tilt),
        n[4],
        w.num(c)
    )
}

/// One `G1` to the tip `tip` with the axes `q`, taking `t` seconds: `F` the tip's speed in
/// mm/min (deg/min of the rotary motion where the printed tip stands, the RS274/NGC rule);
/// nothing if the printed words do not change. With power the controller computes the tip's
/// speed from its joints as for the joint-space dialect: the same coefficients, the move in
/// pieces of its own tip line.
fn tcp_move(w: &mut Writer<'_>, tip: Point3<f64>, q: Axes, t: f64) {
    let from = w.last_axes.replace(q);
    let Some((now, prev)) = w.moved(&Axes::new(tip.x, tip.y, tip.z, q.tilt, q.c)) else {
        return;
    };
    let d: [f64; 5] = std::array::from_fn(|k| now[k] - prev[k]);
    // The feed is the same on every piece: the pieces split the move evenly in time.
    let f = feed_number(rs274_feed(&prev, &now, t));
    match (w.power().is_some() && w.in_cut, from) {
        (true, Some(from)) => {
            let words = |w: &Writer<'_>, fr: f64| -> String {
                let p = Axes::from_array(std::array::from_fn(|k| prev[k] + fr * d[k]));
                tcp_words(w, &Point3::new(p[0], p[1], p[2]), p[3], p[4])
            };
            let (a, b) = (w.printed(&from), w.printed(&q));
            w.powered_pieces(
                &a,
                &b,
                |w, fr, _| {
                    let end = if fr == 1.0 {
                        tcp_words(w, &tip, q.tilt, q.c)
                    } else {
                        words(w, fr)
                    };
                    format!("G1 {end} F{f}")
                },
                t,
            );
        }
        _ => {
            let l = format!("G1 {} F{f}", tcp_words(w, &tip, q.tilt, q.c));
            w.line(&l);
        }
    }
    w.last = Some(now);
}
