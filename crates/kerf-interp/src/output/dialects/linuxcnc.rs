//! `linuxcnc`: LinuxCNC with trivkins and the machine's axis letters: the machine axes,
//! inverse-time feed `G93` (`F = 60 / t` for a block of `t` seconds), `G64 P<q> Q0` on cuts and
//! `G61` on rapids, the safe preamble, `( ... )` comments, `M2`. The beam on `M64`/`M65 P0`
//! (a machine's `M62 P<n>` pierce lit with the immediate `M64 P<n>`), micro-joints with the
//! synchronized `M63`/`M62`, power through HAL (`M67`/`M68`: module docs of `power`), and the
//! controller's own kerf compensation (`G41.1`/`G42.1 D`).

use kerf_kinematics::Axes;
use nalgebra::{Point3, Vector3};

use super::super::writer::Rules;
use super::super::writer::{digital_output, feed_number, Writer};
use super::super::{CutterCompensation, LaserPower, ProcessCodes};
use super::generic::axes_rapid;
use crate::block::Block;

/// LinuxCNC, joint space.
pub(in crate::output) struct Linuxcnc;

impl Rules for Linuxcnc {
    fn name(&self) -> &'static str {
        "linuxcnc"
    }

    fn beam_codes(&self) -> (&'static str, &'static str) {
        ("M64 P0", "M65 P0")
    }

    fn comment(&self, text: &str) -> String {
        format!("({text})")
    }

    fn describe(&self, n: [&str; 5]) -> (String, String, &'static str) {
        (
            format!(
                "kerf LinuxCNC program: trivkins machine axes {} {} {} {} {}, no tool-tip control",
                n[0], n[1], n[2], n[3], n[4]
            ),
            "feed: G93 inverse time on every cutting block, F = 60 / planned block time in s,\nfeed: so the tool tip moves at kerf's planned speed; rapids G0 in exact path G61".to_string(),
            "arcs written as G1 chords",
        )
    }

    fn preamble(&self, w: &mut Writer<'_>) {
        w.line("G17 G21 G40 G49 G54 G80 G90 G94");
        w.line("G93");
        w.line("G61");
    }

    fn power_header(&self, w: &mut Writer<'_>) {
        w.comment("power: HAL power = clamp[E0 x tip speed in mm/s, E1, 100], E0 = % per mm/s, E1 = floor [M68 E1 = pierce power]");
        w.comment("power: HAL tip speed = |d[X,Y,Z]/dt + [E2,E3,E4] d[tilt]/dt + [E5,E6,E7] dC/dt|, rotary rates in deg/s");
        w.comment("power: E2..E7 mm/deg, set with M67 [synchronized with the next block] where the rotary axes move");
    }

    fn rapid(&self, w: &mut Writer<'_>, _p: Point3<f64>, q: Axes, _u: Vector3<f64>) {
        axes_rapid(w, q);
    }

    fn pierce_beam_on(&self, line: String) -> String {
        pierce_beam_on(line)
    }

    fn blend_on(&self, w: &mut Writer<'_>) {
        blend_on(w);
    }

    fn descent(
        &self,
        w: &mut Writer<'_>,
        b: &Block,
        _start: Point3<f64>,
        _u: Vector3<f64>,
        t: f64,
        _h: f64,
    ) {
        joint_move(w, b.start_axes, t);
    }

    fn blend_off(&self, w: &mut Writer<'_>) {
        w.line("G61");
    }

    fn cut(&self, w: &mut Writer<'_>, b: &Block, t: f64) {
        w.block_pieces(b, t, |w, _, q, dt, _| joint_move(w, q, dt));
    }

    fn pierce_power(&self, w: &mut Writer<'_>, power: &LaserPower) {
        pierce_power(w, power);
    }

    fn cut_power(&self, w: &mut Writer<'_>, power: &LaserPower) {
        cut_power(w, power);
    }

    fn power_off(&self, w: &mut Writer<'_>) {
        power_off(w);
    }

    fn joint_codes(
        &self,
        process: &ProcessCodes,
    ) -> std::result::Result<(Vec<String>, Vec<String>), &'static str> {
        joint_codes(process)
    }

    fn controller_compensation(&self) -> bool {
        true
    }

    /// `G41.1 D<kerf>` (left) or `G42.1 D<kerf>` (right): the diameter in the block, no
    /// tool table.
    fn compensation_on(&self, c: &CutterCompensation) -> Vec<String> {
        let g = if c.left { "G41.1" } else { "G42.1" };
        vec![format!("{g} D{}", feed_number(c.kerf_width_mm))]
    }

    /// `G41.1` offsets X and Y only.
    fn compensation_xy_only(&self) -> bool {
        true
    }

    fn compensation_words(&self, kerf_width_mm: f64) -> String {
        format!("G41.1/G42.1 D{kerf_width_mm}")
    }

    /// `G40` before the beam's off codes: LinuxCNC sets no digital output while it
    /// compensates.
    fn compensation_off(&self) -> (Vec<String>, bool) {
        (vec!["G40".to_string()], true)
    }

    fn footer(&self, w: &mut Writer<'_>) {
        w.line("M2");
    }
}

/// One `G1` in inverse time to `q`, taking `t` seconds; nothing if the printed axes do not
/// change. With power (and no compensation running) the controller computes the tip's speed
/// from the joints: the rotary coefficients go with the block where stale ones would misjudge
/// its tip travel by more than the writer's power step, the block in pieces of its own joint
/// line where they turn inside it.
fn joint_move(w: &mut Writer<'_>, q: Axes, t: f64) {
    let Some((qp, prev)) = w.moved(&q) else {
        return;
    };
    if w.power().is_some() && w.in_cut && !w.compensating {
        w.powered_pieces(
            &prev,
            &qp,
            |w, f, dt| {
                let end = if f == 1.0 {
                    q
                } else {
                    w.printed(&prev.lerp(&qp, f))
                };
                format!("G1 {} F{}", w.axis_words(&end), feed_number(60.0 / dt))
            },
            t,
        );
    } else {
        let l = format!("G1 {} F{}", w.axis_words(&q), feed_number(60.0 / t));
        w.line(&l);
    }
    w.last = Some(qp);
    w.last_axes = Some(q);
}

/// The pierce is lit at once: a synchronized `M62` would wait for the next move and the dwell
/// would run dark, so it is written as the immediate `M64` on the same output.
pub(super) fn pierce_beam_on(line: String) -> String {
    match digital_output(&line) {
        Some((62, p)) => format!("M64 P{p}"),
        _ => line,
    }
}

/// `G64 P<blend> Q0` for the cut.
pub(super) fn blend_on(w: &mut Writer<'_>) {
    let l = format!("G64 P{} Q0", w.opts.blend_tolerance_mm);
    w.line(&l);
}

/// The pierce power (`M68 E1`) with the speed scale at zero, the rotary coefficients reset.
pub(super) fn pierce_power(w: &mut Writer<'_>, power: &LaserPower) {
    let pierce = Writer::pierce_number(power);
    w.line("M68 E0 Q0");
    w.line(&format!("M68 E1 Q{pierce}"));
    if w.coeffs != [0.0; 6] {
        for j in 2..8 {
            w.line(&format!("M68 E{j} Q0"));
        }
        w.coeffs = [0.0; 6];
    }
}

/// The cut's floor (`E1`) and power per mm/s (`E0`), synchronized with the descent.
pub(super) fn cut_power(w: &mut Writer<'_>, power: &LaserPower) {
    let floor = w.floor_number(power);
    let k = feed_number(power.per_mm_s(w.factor));
    w.line(&format!("M67 E1 Q{floor}"));
    w.line(&format!("M67 E0 Q{k}"));
}

/// Every power output back to zero.
pub(super) fn power_off(w: &mut Writer<'_>) {
    for j in 0..8 {
        w.line(&format!("M68 E{j} Q0"));
    }
}

/// The synchronized `M63`/`M62` on the outputs the machine's beam codes switch (`M62`-`M65
/// P<n>` only).
pub(super) fn joint_codes(
    process: &ProcessCodes,
) -> std::result::Result<(Vec<String>, Vec<String>), &'static str> {
    let map = |lines: &[String], m: u32| -> Option<Vec<String>> {
        lines
            .iter()
            .map(|l| digital_output(l).map(|(_, p)| format!("M{m} P{p}")))
            .collect()
    };
    match (map(&process.beam_off, 63), map(&process.beam_on, 62)) {
        (Some(off), Some(on)) if !off.is_empty() && !on.is_empty() => Ok((off, on)),
        _ => Err("micro-joints on LinuxCNC need beam codes of the form M62-M65 P<n> (switched with motion as M63/M62 at the joints)"),
    }
}
