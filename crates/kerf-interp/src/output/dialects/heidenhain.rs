//! `heidenhain` and `heidenhain-axes`: HEIDENHAIN Klartext (conversational) for a TNC with
//! tool center point management. `FUNCTION TCPM F TCP AXIS POS PATHCTRL AXIS` for the whole
//! program: `X Y Z` the tool tip in the active preset (the workpiece frame), `F` the tip's
//! speed, the rotary axes interpolated linearly in each block (as kerf's poses are joined).
//! `heidenhain` writes `LN X Y Z TX TY TZ F` (the tip with the unit tool direction; the TNC
//! chooses the rotary solution of each direction itself, which is kerf's where it takes the
//! nearest one, as kerf does); `heidenhain-axes` writes `L X Y Z <tilt> C F` with the rotary
//! axes kerf solved (its limits, its side of a singularity). Every block is numbered, the
//! program framed by `BEGIN PGM KERF MM` and `END PGM KERF MM`; `;` comments (a `~`, which
//! would continue a block onto the next line, is escaped); coordinates with their sign and
//! four decimals (the TNC's input resolution), directions with seven; `FMAX` rapids with
//! `R0`; the pierce dwell `CYCL DEF 9.0 DWELL TIME` / `CYCL DEF 9.1 DWELL <s>`; the contour
//! tolerance `CYCL DEF 32` with `T` half the budget's controller-blending term and `TA` the
//! other half turned into degrees at the pivot length (as Sinumerik's `CTOL`/`OTOL`), rounded
//! down to the TNC's four decimals (where that leaves nothing, its least, 0.0001, and the header
//! says the controller may then blend more than the budget); the beam
//! codes as M-function blocks of their own; `FUNCTION RESET TCPM`, `M30` at the end. No
//! `BLK FORM` and no `TOOL CALL`: the active tool's length must put the tip where kerf's
//! machine file does (the header says so).
//!
//! Power that follows the speed is not written: S is a `TOOL CALL` word only, and Q parameters
//! are computed ahead of the motion, not with it; the header says the technology's power is
//! not commanded, and the machine's laser control must follow the path speed itself.

use kerf_kinematics::Axes;
use nalgebra::{Point3, Vector3};

use super::super::writer::Rules;
use super::super::writer::{rs274_feed, Writer};
use crate::block::Block;
use crate::error::Result;
use crate::model::AxisModel;

/// The program's name in `BEGIN PGM` / `END PGM`.
const PROGRAM: &str = "KERF";

/// HEIDENHAIN Klartext under `FUNCTION TCPM`: `LN` with the tool direction, or `L` with the
/// rotary axes.
pub(in crate::output) struct Heidenhain {
    /// `L` with the rotary axes (`heidenhain-axes`) instead of `LN` with `TX TY TZ`.
    pub(in crate::output) axes: bool,
}

impl Rules for Heidenhain {
    fn name(&self) -> &'static str {
        if self.axes {
            "heidenhain-axes"
        } else {
            "heidenhain"
        }
    }

    /// `; text`, with `~` escaped: a line that ends in `~` continues its block on the next
    /// line, which would take the next block into the comment.
    fn comment(&self, text: &str) -> String {
        format!("; {}", text.replace('~', "\\u{7e}"))
    }

    fn max_decimals(&self) -> usize {
        4
    }

    fn machine_lines(&self, _model: &dyn AxisModel) -> Result<Vec<String>> {
        Ok(vec![
            "tool center point management: FUNCTION TCPM; the TNC's kinematics description must be the machine's, and the active tool's length must put its tip at kerf's tool tip [no TOOL CALL is written]".to_string(),
        ])
    }

    fn opening(&self) -> &'static [&'static str] {
        &["BEGIN PGM KERF MM"]
    }

    fn describe(&self, n: [&str; 5]) -> (String, String, &'static str) {
        let words = if self.axes {
            format!(
                "L X Y Z {} {}: the tool tip and the rotary axes",
                n[3], n[4]
            )
        } else {
            "LN X Y Z TX TY TZ: the tool tip and the unit tool direction [the TNC chooses the rotary solution]".to_string()
        };
        (
            format!("kerf HEIDENHAIN Klartext program: {words}, in the active preset"),
            format!(
                "feed: FUNCTION TCPM F TCP, F in mm/min of the tool tip, the block's mean planned speed; where the tip stands F is deg/min of the rotary motion;\nfeed: CYCL DEF 32 T and TA from the budget's controller_blending term;\nfeed: rapids FMAX split so that the tip follows kerf's joint-space traverse within {} mm{};\nfeed: coordinates to 4 decimals, rotary axes to 4, directions to 7",
                crate::RAPID_TCP_TOLERANCE_MM,
                if self.axes { "" } else { " where the TNC takes kerf's rotary solution of each direction" }
            ),
            "arcs written as line chords",
        )
    }

    fn units_word(&self) -> &'static str {
        "MM"
    }

    fn preamble(&self, w: &mut Writer<'_>) {
        let o = w.opts;
        w.line("FUNCTION TCPM F TCP AXIS POS PATHCTRL AXIS");
        w.line("CYCL DEF 32.0 TOLERANCE");
        let t = o.blend_tolerance_mm / 2.0;
        let (t_word, t_over) = tolerance_word(t);
        w.line(&format!("CYCL DEF 32.1 T{t_word}"));
        if t_over {
            w.comment(&format!(
                "tolerance: T {t_word} mm is the TNC's least, above the budget's half of the blending term [{t} mm]: the controller may blend more than the budget says"
            ));
        }
        match o.pivot_length_mm.filter(|l| l.is_finite() && *l > 0.0) {
            Some(l) => {
                let ta = (t / l).to_degrees();
                let (ta_word, ta_over) = tolerance_word(ta);
                w.line(&format!("CYCL DEF 32.2 HSC-MODE:0 TA{ta_word}"));
                if ta_over {
                    let at_tip = ta_word.parse::<f64>().unwrap_or(1e-4).to_radians() * l;
                    w.comment(&format!(
                        "tolerance: TA {ta_word} deg is the TNC's least: at the pivot length {l} mm it allows {at_tip:.6} mm at the tip, above the budget's half of the blending term [{t} mm]"
                    ));
                }
            }
            None => {
                w.line("CYCL DEF 32.2 HSC-MODE:0");
                w.comment("tolerance: TA not written [no pivot length known]: the TNC's own rotary tolerance applies, outside the budget");
            }
        }
        // What the four decimals cost: half a unit of the last decimal on each of X Y Z. Under
        // TCPM the rotary words (or the direction) set the tool's orientation about the tip,
        // so their rounding turns the tool, it does not move the tip.
        let xyz = 3f64.sqrt() * 0.5e-4;
        let orientation = if self.axes {
            "the rotary axes' 0.00005 deg each turn the tool about it"
        } else {
            "the directions' seven decimals turn the tool about it by 1e-7 rad"
        };
        w.comment(&format!(
            "rounding: X Y Z to four decimals move the tip by at most {xyz:.6} mm, not in the budget; {orientation}"
        ));
    }

    fn power_header(&self, _w: &mut Writer<'_>) {}

    fn power_refusal(&self) -> Option<&'static str> {
        Some("a Klartext program has no power word that acts with the motion [S belongs to TOOL CALL, Q parameters are computed ahead of it]: the machine's laser control must follow the path speed itself")
    }

    fn rapid(&self, w: &mut Writer<'_>, p: Point3<f64>, q: Axes, _u: Vector3<f64>) {
        let l = if self.axes { "L" } else { "LN" };
        w.tip_rapid(l, p, q, |w, tip, a| {
            format!("{} R0 FMAX", self.words(w, tip, a))
        });
    }

    fn dwell(&self, s: f64) -> String {
        format!(
            "CYCL DEF 9.0 DWELL TIME\nCYCL DEF 9.1 DWELL {}",
            dwell_number(s)
        )
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
        self.cut_move(w, start, b.start_axes, t);
    }

    fn cut(&self, w: &mut Writer<'_>, b: &Block, t: f64) {
        w.block_pieces(b, t, |w, s, q, dt, _| {
            self.cut_move(w, b.pose_at(s).0, q, dt);
        });
    }

    fn footer(&self, w: &mut Writer<'_>) {
        w.line("FUNCTION RESET TCPM");
        w.line("M30");
        w.line(&format!("END PGM {PROGRAM} MM"));
    }

    /// Every line numbered from 0, as the TNC numbers its blocks.
    fn finish(&self, text: String) -> String {
        let mut out = String::with_capacity(text.len() + text.len() / 4);
        for (i, l) in text.lines().enumerate() {
            out.push_str(&format!("{i} {l}\n"));
        }
        out
    }
}

impl Heidenhain {
    /// The position words: the tip with the rotary axes (`L`) or with the tool direction
    /// (`LN`, from the axes through the machine's kinematics).
    fn words(&self, w: &Writer<'_>, tip: &Point3<f64>, q: &Axes) -> String {
        let xyz = format!(
            "X{} Y{} Z{}",
            signed(w, tip.x),
            signed(w, tip.y),
            signed(w, tip.z)
        );
        if self.axes {
            format!(
                "{xyz} {}{} {}{}",
                w.names[3],
                signed(w, q[3]),
                w.names[4],
                signed(w, q[4])
            )
        } else {
            let u = w.model.tool_axis(q.tilt, q.c).normalize();
            format!(
                "{xyz} TX{} TY{} TZ{}",
                direction(u.x),
                direction(u.y),
                direction(u.z)
            )
        }
    }

    /// One `L`/`LN` to the tip `tip` with the axes `q`, taking `t` seconds: `F` the tip's
    /// speed (deg/min of the rotary motion where the printed tip stands); nothing if the
    /// printed position does not change.
    fn cut_move(&self, w: &mut Writer<'_>, tip: Point3<f64>, q: Axes, t: f64) {
        w.last_axes = Some(q);
        let Some((now, prev)) = w.moved(&Axes::new(tip.x, tip.y, tip.z, q.tilt, q.c)) else {
            return;
        };
        let f = rs274_feed(&prev, &now, t);
        let l = format!(
            "{} {} F{}",
            if self.axes { "L" } else { "LN" },
            self.words(w, &tip, &q),
            feed(f)
        );
        w.line(&l);
        w.last = Some(now);
    }
}

/// A coordinate with its sign, as the TNC writes it (`X+12.5`, `X-0.25`; zero is `+0`).
fn signed(w: &Writer<'_>, v: f64) -> String {
    let t = w.num(v);
    if t.starts_with('-') {
        t
    } else {
        format!("+{t}")
    }
}

/// A component of a unit direction with its sign and seven decimals (the manuals' `LN`
/// blocks), never `-0`.
fn direction(v: f64) -> String {
    let t = format!("{v:+.7}");
    if t.bytes().skip(1).all(|c| c == b'0' || c == b'.') {
        "+0.0000000".to_string()
    } else {
        t
    }
}

/// A feed in mm/min (deg/min) with three decimals, at least 0.001 (never `F0`, which the
/// TNC reads as no feed).
fn feed(f: f64) -> String {
    format!("{:.3}", f.max(0.001))
}

/// A tolerance of `CYCL DEF 32` (mm or degrees) as written: four decimals, rounded down so
/// that the controller keeps within the budget; where that would be 0 the TNC's least,
/// 0.0001, and `true`: the written tolerance is above `v` (the header says so).
fn tolerance_word(v: f64) -> (String, bool) {
    let down = (v * 1e4).floor() / 1e4;
    if down >= 1e-4 {
        (trimmed(down, 4), false)
    } else {
        ("0.0001".to_string(), true)
    }
}

/// A dwell in seconds: three decimals, rounded up (a pierce never shorter than asked).
fn dwell_number(s: f64) -> String {
    trimmed((s * 1e3).ceil() / 1e3, 3)
}

/// `v` with `decimals` decimals, trailing zeros (and a bare point) dropped.
fn trimmed(v: f64, decimals: usize) -> String {
    let t = format!("{v:.decimals$}");
    t.trim_end_matches('0').trim_end_matches('.').to_string()
}

#[cfg(test)]
mod tests {
    use super::super::super::{Dialect, GcodeOptions};
    use super::*;

    /// The manuals' example block `L X+31.737 Y+21.954 Z+33.165 B+12.357 C+5.896 F1000`
    /// (TNC 426/430 and TNC 620 user's manuals, "Block format with rotary axes"), written by
    /// the dialect for the same tip, axes and feed on a B/C head: the same words, each number
    /// to the dialect's four decimals (three for `F`).
    #[test]
    fn the_manuals_rotary_axis_block() {
        let path = concat!(
            env!("CARGO_MANIFEST_DIR"),
            "/../../fixtures/machines/bc_head_5axiskins.json"
        );
        let model =
            crate::MachineModel::new(kerf_kinematics::Machine::read(path).expect("machine"))
                .expect("model");
        let opts = GcodeOptions::new(Dialect::HeidenhainAxes, 1000.0);
        let mut w = Writer::new(
            &model,
            &opts,
            Dialect::HeidenhainAxes.default_process(),
            None,
            Vec::new(),
        );
        let tip = Point3::new(31.737, 21.954, 33.165);
        let q = Axes::new(0.0, 0.0, 0.0, 12.357, 5.896);
        // 1000 mm/min: 10 mm of tip travel in 0.6 s from a tip 10 mm away along X.
        w.last = Some(Axes::new(21.737, 21.954, 33.165, 12.357, 5.896));
        Heidenhain { axes: true }.cut_move(&mut w, tip, q, 0.6);
        assert_eq!(
            w.finish(),
            "L X+31.7370 Y+21.9540 Z+33.1650 B+12.3570 C+5.8960 F1000.000\n"
        );
    }

    #[test]
    fn numbers_as_the_tnc_writes_them() {
        assert_eq!(direction(-0.8764339), "-0.8764339");
        assert_eq!(direction(-1e-9), "+0.0000000");
        assert_eq!(direction(0.25903194), "+0.2590319");
        assert_eq!(tolerance_word(0.0025), ("0.0025".to_string(), false));
        // Down: within the budget.
        assert_eq!(tolerance_word(0.00079), ("0.0007".to_string(), false));
        // Below the TNC's least: its least, flagged as above the budget.
        assert_eq!(tolerance_word(1e-7), ("0.0001".to_string(), true));
        assert_eq!(dwell_number(0.2), "0.2");
        assert_eq!(dwell_number(0.2001), "0.201"); // up: never a shorter pierce
        assert_eq!(feed(0.0), "0.001");
    }
}
