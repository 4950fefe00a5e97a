//! What a G-code dialect decides, as one trait: each dialect is one file under `dialects/`
//! implementing [`Rules`], registered in [`Dialect::rules`](super::Dialect) (the one `match`
//! on the dialect). The writer ([`Writer`]) holds what every program shares: the header, the
//! framing of every cut (a rapid to the pierce point, the beam on, the dwell, the descent, the
//! cut, the beam off), number formatting, the power's bookkeeping and the pieces a raw-axis
//! block is written in; it asks the dialect for everything else.

use nalgebra::{Point3, Vector3};

use super::writer::Writer;
use super::{LaserPower, ProcessCodes};
use crate::block::Block;
use crate::error::Result;
use crate::model::AxisModel;

/// The decisions of one dialect. Methods with a default are the RS274/NGC habit most
/// controllers share.
pub(super) trait Rules: Sync {
    /// The name as the CLI spells it (`--dialect`).
    fn name(&self) -> &'static str;

    /// True where blocks may join only neighbouring poses (no arcs, no lines merged over
    /// several poses): see [`Dialect::raw_axes`](super::Dialect::raw_axes).
    fn joins_poses_only(&self) -> bool {
        true
    }

    /// The beam codes used where the machine file names none: `(on, off)`.
    fn beam_codes(&self) -> (&'static str, &'static str) {
        ("M3", "M5")
    }

    /// One whole-line comment of already escaped `text`.
    fn comment(&self, text: &str) -> String {
        format!("; {text}")
    }

    /// Checks that the dialect can program this machine and returns the header lines that say
    /// what the controller must be set up with (none by default).
    ///
    /// # Errors
    /// [`crate::InterpError::DialectMachine`] naming the mismatch.
    fn machine_lines(&self, _model: &dyn AxisModel) -> Result<Vec<String>> {
        Ok(Vec::new())
    }

    /// The lines before the header comments (a tape start, a program number); none by
    /// default.
    fn opening(&self) -> &'static [&'static str] {
        &[]
    }

    /// The header's title, its feed semantics (lines separated by `\n`) and how arcs are
    /// written, for the axis names `names`.
    fn describe(&self, names: [&str; 5]) -> (String, String, &'static str);

    /// The most decimals a coordinate or an angle is written with (the controller's input
    /// resolution); the options' `decimals` are cut to it.
    fn max_decimals(&self) -> usize {
        12
    }

    /// The word of the metric unit in the header (`G21`).
    fn units_word(&self) -> &'static str {
        "G21"
    }

    /// The lines after the header comments, before the first beam-off.
    fn preamble(&self, w: &mut Writer<'_>);

    /// The header's lines on how the dialect commands power that follows the speed (after the
    /// rule itself).
    fn power_header(&self, w: &mut Writer<'_>);

    /// A rapid to the axes `q` (tip `p`, tool axis `u`).
    fn rapid(&self, w: &mut Writer<'_>, p: Point3<f64>, q: [f64; 5], u: Vector3<f64>);

    /// A beam-on line as written at the pierce (where it must act at once).
    fn pierce_beam_on(&self, line: String) -> String {
        line
    }

    /// The dwell of `s` seconds.
    fn dwell(&self, s: f64) -> String {
        format!("G4 P{s}")
    }

    /// The controller's blending switched on for the cut, after the pierce dwell.
    fn blend_on(&self, _w: &mut Writer<'_>) {}

    /// The descent from the pierce point to the cut's start (tip `start`, tool axis `u`), `h`
    /// mm in `t` seconds at the cutting feed.
    fn descent(
        &self,
        w: &mut Writer<'_>,
        b: &Block,
        start: Point3<f64>,
        u: Vector3<f64>,
        t: f64,
        h: f64,
    );

    /// The blending back to exact path after the cut's beam-off.
    fn blend_off(&self, _w: &mut Writer<'_>) {}

    /// The cutting block `b`, taking `t` seconds.
    fn cut(&self, w: &mut Writer<'_>, b: &Block, t: f64);

    /// Why the dialect cannot command a power that follows the speed (the header says it and
    /// the program switches the beam only), or `None` where it can.
    fn power_refusal(&self) -> Option<&'static str> {
        None
    }

    /// The pierce power before the beam comes on: `S<percent>` by default (the cutting moves
    /// then carry `S` where the planned power changes, [`Writer::s_word`]).
    fn pierce_power(&self, w: &mut Writer<'_>, power: &LaserPower) {
        let l = format!("S{}", Writer::pierce_number(power));
        w.line(&l);
    }

    /// The cut's power rule after the dwell, before the descent: nothing by default (the `S`
    /// words come with the moves).
    fn cut_power(&self, _w: &mut Writer<'_>, _power: &LaserPower) {}

    /// The power back to zero at the end: `S0` by default.
    fn power_off(&self, w: &mut Writer<'_>) {
        w.line("S0");
    }

    /// The lines that switch the beam off and on again over a micro-joint (synchronized with
    /// motion), or why the dialect cannot: the machine's own beam codes between the blocks by
    /// default.
    fn joint_codes(
        &self,
        process: &ProcessCodes,
    ) -> std::result::Result<(Vec<String>, Vec<String>), &'static str> {
        Ok((process.beam_off.clone(), process.beam_on.clone()))
    }

    /// True where the controller's kerf compensation can be written (`G41.1`/`G42.1`).
    fn controller_compensation(&self) -> bool {
        false
    }

    /// The program's last lines.
    fn footer(&self, w: &mut Writer<'_>);

    /// The whole program text as written to the file (block numbers where the controller
    /// wants them); the text itself by default.
    fn finish(&self, text: String) -> String {
        text
    }
}

/// The default process codes of a dialect's rules.
pub(super) fn default_process(rules: &dyn Rules) -> ProcessCodes {
    let (on, off) = rules.beam_codes();
    ProcessCodes {
        beam_on: vec![on.to_string()],
        beam_off: vec![off.to_string()],
        pierce_dwell_s: 0.2,
        pierce_standoff: 1.5,
    }
}
