//! `generic`: `G1 X Y Z A C F` with the machine axes, `G94` feed in the RS274/NGC sense (`F`
//! is mm/min of the combined X Y Z machine-axis motion, deg/min of the rotary motion on blocks
//! without it), chosen so that each block takes its planned time; `;` comments, `M30`. Power:
//! `S` per block from kerf's planned tip speed.

use kerf_kinematics::Axes;
use nalgebra::{Point3, Vector3};

use super::super::writer::Rules;
use super::super::writer::{feed_number, rs274_feed, Writer};
use crate::block::Block;

/// The generic dialect.
pub(in crate::output) struct Generic;

impl Rules for Generic {
    fn name(&self) -> &'static str {
        "generic"
    }

    fn describe(&self, n: [&str; 5]) -> (String, String, &'static str) {
        (
            format!(
                "kerf generic 5-axis program: machine axes {} {} {} {} {}, no tool-tip control",
                n[0], n[1], n[2], n[3], n[4]
            ),
            format!(
                "feed: G94, F in mm/min of the combined {} {} {} machine-axis motion, NOT of the tool tip;\nfeed: on blocks without {} {} {} motion F is deg/min of the combined rotary motion (RS274/NGC rule);\nfeed: each F makes its block take kerf's planned time",
                n[0], n[1], n[2], n[0], n[1], n[2]
            ),
            "arcs written as G1 chords",
        )
    }

    fn preamble(&self, w: &mut Writer<'_>) {
        w.line("G17 G21 G40 G90 G94");
    }

    fn power_header(&self, w: &mut Writer<'_>) {
        w.comment("power: S = % per block from kerf's planned tip speed");
    }

    fn rapid(&self, w: &mut Writer<'_>, _p: Point3<f64>, q: Axes, _u: Vector3<f64>) {
        axes_rapid(w, q);
    }

    fn descent(
        &self,
        w: &mut Writer<'_>,
        b: &Block,
        _start: Point3<f64>,
        _u: Vector3<f64>,
        t: f64,
        h: f64,
    ) {
        axes_move(w, b.start_axes, t, h);
    }

    fn cut(&self, w: &mut Writer<'_>, b: &Block, t: f64) {
        w.block_pieces(b, t, |w, _, q, dt, tip_mm| axes_move(w, q, dt, tip_mm));
    }

    fn footer(&self, w: &mut Writer<'_>) {
        w.line("M30");
    }
}

/// A `G0` to the machine axes `q` (the raw-axis dialects).
pub(super) fn axes_rapid(w: &mut Writer<'_>, q: Axes) {
    let l = format!("G0 {}", w.axis_words(&q));
    w.line(&l);
    w.last = Some(w.printed(&q));
    w.last_axes = Some(q);
}

/// One generic `G1` to `q`, taking `t` seconds while the tip moves `tip_mm`: `F` by the
/// RS274/NGC rule, the planned power as `S` where it changed; nothing if the printed axes do
/// not change.
fn axes_move(w: &mut Writer<'_>, q: Axes, t: f64, tip_mm: f64) {
    let Some((qp, prev)) = w.moved(&q) else {
        return;
    };
    let f = rs274_feed(&prev, &qp, t);
    let s_word = w.s_word(tip_mm, t);
    let l = format!("G1 {} F{}{s_word}", w.axis_words(&q), feed_number(f));
    w.line(&l);
    w.last = Some(qp);
    w.last_axes = Some(q);
}
