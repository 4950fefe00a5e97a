//! `fanuc` and `fanuc-ijk`: Fanuc tool center point control. The tool tip `X Y Z` in the
//! workpiece frame (`G54`) with the rotary axes under `G43.4` (type 1, any machine) or with
//! the tool direction `I J K` under `G43.5` (type 2: head machines only; a table machine raises
//! alarm PS5421 with `I J K`, so `fanuc-ijk` refuses one by name); `G05.1 Q1` (AI contour
//! control, the look-ahead) on for the program, `G49` and `G05.1 Q0` at its end; `G94` with `F`
//! the tip's mean planned speed of the block (the tip's speed is what tool center point
//! control holds; deg/min of the rotary motion where the tip stands); `G04 X` dwell in seconds;
//! `( ... )` comments; `%`, an `O` number and `M30`. The corner rounding of AI contour control is
//! the machine's parameter, not the program's: the header says so. Power as `S` per block
//! from kerf's planned tip speed (a laser's power channel on Fanuc is the machine builder's;
//! `S` is the common one). Rapids: `G00` under tool center point control moves the tip
//! straight or the axes linearly by the machine's parameter; under `G43.4` either way each
//! rapid is split so that it follows kerf's checked joint-space traverse (its pieces' ends lie
//! on it, the tip chords within [`crate::RAPID_TCP_TOLERANCE_MM`] of it). Under `G43.5` the
//! control chooses the rotary solution of each `I J K` itself: the traverse holds where it
//! chooses kerf's (the nearest, as kerf does), and where the tip stands the feed kerf writes
//! is deg/min of kerf's rotary motion, which the program does not name.

use kerf_kinematics::Axes;
use nalgebra::{Point3, Vector3};

use super::super::writer::Rules;
use super::super::writer::{feed_number, rs274_feed, Writer};
use super::linuxcnc_tcp::tcp_words;
use crate::block::Block;
use crate::error::{InterpError, Result};
use crate::model::AxisModel;

/// Fanuc tool center point control: `G43.4` with rotary words, or `G43.5` with `I J K`.
pub(in crate::output) struct Fanuc {
    /// `G43.5` with the tool direction (`fanuc-ijk`) instead of `G43.4` with the rotary axes.
    pub(in crate::output) ijk: bool,
}

impl Rules for Fanuc {
    fn name(&self) -> &'static str {
        if self.ijk {
            "fanuc-ijk"
        } else {
            "fanuc"
        }
    }

    /// `( ... )`, with `%` written `pct`: a Fanuc control reads `%` as the end of the record
    /// (the tape end), wherever it stands.
    fn comment(&self, text: &str) -> String {
        format!("({})", text.replace('%', "pct"))
    }

    fn machine_lines(&self, model: &dyn AxisModel) -> Result<Vec<String>> {
        if self.ijk {
            let kind = model.machine().map(|m| m.kinematics.type_name());
            if !matches!(kind, Some("ac-head" | "fork-head")) {
                return Err(InterpError::DialectMachine {
                    dialect: "fanuc-ijk",
                    reason: format!(
                        "the machine is a {}: G43.5 with I J K is for head machines (a table machine raises alarm PS5421); use the fanuc dialect (G43.4, rotary axes)",
                        kind.unwrap_or("model without a kerf.machine/1 type")
                    ),
                });
            }
        }
        Ok(vec![format!(
            "tool center point control: {}, tool length offset H1; the machine's TCP parameters must be its kinematics",
            if self.ijk { "G43.5 [type 2, tool direction I J K]" } else { "G43.4 [type 1, rotary axes]" }
        )])
    }

    fn describe(&self, n: [&str; 5]) -> (String, String, &'static str) {
        let words = if self.ijk {
            "I J K the tool direction".to_string()
        } else {
            format!("{} {} the rotary axes", n[3], n[4])
        };
        (
            format!("kerf Fanuc program: tool center point control, X Y Z the tool tip in the workpiece frame G54, {words}"),
            format!(
                "feed: G94, F in mm/min of the tool tip, the block's mean planned speed; where the tip stands F is deg/min of the rotary motion;\nfeed: look-ahead G05.1 Q1; its corner rounding is the machine's parameter, not this program's: the budget's controller_blending term assumes it no larger;\nfeed: rapids G00 split so that they follow kerf's joint-space traverse within {} mm",
                crate::RAPID_TCP_TOLERANCE_MM
            ),
            "arcs written as G01 chords",
        )
    }

    fn opening(&self) -> &'static [&'static str] {
        &["%", "O1000"]
    }

    fn preamble(&self, w: &mut Writer<'_>) {
        w.line("G17 G21 G40 G49 G80 G90 G94");
        w.line("G54");
        w.line("G05.1 Q1");
        w.line(if self.ijk { "G43.5 H1" } else { "G43.4 H1" });
    }

    fn power_header(&self, w: &mut Writer<'_>) {
        w.comment("power: S = % per block from kerf's planned tip speed");
    }

    fn rapid(&self, w: &mut Writer<'_>, p: Point3<f64>, q: Axes, _u: Vector3<f64>) {
        w.tip_rapid("G00", p, q, |w, tip, a| self.words(w, tip, a));
    }

    /// `G04 X` in seconds, always with a decimal point: a Fanuc control reads `X1` without
    /// one in its least input increment (1 ms), so a 1 s dwell would run 1000 times too short.
    fn dwell(&self, s: f64) -> String {
        format!("G04 X{s:.3}")
    }

    fn descent(
        &self,
        w: &mut Writer<'_>,
        b: &Block,
        start: Point3<f64>,
        _u: Vector3<f64>,
        t: f64,
        h: f64,
    ) {
        self.cut_move(w, start, b.start_axes, t, h);
    }

    fn cut(&self, w: &mut Writer<'_>, b: &Block, t: f64) {
        w.block_pieces(b, t, |w, s, q, dt, tip_mm| {
            self.cut_move(w, b.pose_at(s).0, q, dt, tip_mm);
        });
    }

    fn footer(&self, w: &mut Writer<'_>) {
        w.line("G49");
        w.line("G05.1 Q0");
        w.line("M30");
        w.line("%");
    }
}

impl Fanuc {
    /// The position words: the tip with the rotary axes (`G43.4`) or the tool direction
    /// (`G43.5`, from the axes through the machine's kinematics).
    fn words(&self, w: &Writer<'_>, tip: &Point3<f64>, q: &Axes) -> String {
        if self.ijk {
            let u = w.model.tool_axis(q.tilt, q.c);
            format!(
                "X{} Y{} Z{} I{} J{} K{}",
                w.num(tip.x),
                w.num(tip.y),
                w.num(tip.z),
                w.num(u.x),
                w.num(u.y),
                w.num(u.z)
            )
        } else {
            tcp_words(w, tip, q.tilt, q.c)
        }
    }

    /// One `G01` to the tip `tip` with the axes `q`, taking `t` seconds over `tip_mm` of tip
    /// travel: `F` the tip's speed (deg/min of the rotary motion where the printed tip stands),
    /// the planned power as `S` where it changed; nothing if the printed position does not
    /// change.
    fn cut_move(&self, w: &mut Writer<'_>, tip: Point3<f64>, q: Axes, t: f64, tip_mm: f64) {
        w.last_axes = Some(q);
        let Some((now, prev)) = w.moved(&Axes::new(tip.x, tip.y, tip.z, q.tilt, q.c)) else {
            return;
        };
        let f = rs274_feed(&prev, &now, t);
        let s_word = w.s_word(tip_mm, t);
        let l = format!(
            "G01 {} F{}{s_word}",
            self.words(w, &tip, &q),
            feed_number(f)
        );
        w.line(&l);
        w.last = Some(now);
    }
}
