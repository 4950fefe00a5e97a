//! `sinumerik`: Sinumerik-style `TRAORI`: the tool tip `X Y Z` and the orientation vector
//! `A3= B3= C3=` in workpiece coordinates (`ORIWKS`, `ORIVECT`), arcs as `CIP` through the
//! intermediate point, `G54`, `SOFT`, `G642` with `CTOL`/`OTOL` from the blending term, `F`
//! the tip's mean planned speed of the block (modal), `;` comments, `TRAFOOF` and `M30`. Rapids
//! `G0` under `RTLION` and `G60`, split until their tips follow kerf's traverse (a straight move
//! of the machine's axes) within [`crate::RAPID_TCP_TOLERANCE_MM`]. Power
//! by the synchronized action `SYNFCT` on `$AC_VACTW` with `FCTDEF` per cut (written to
//! Siemens' documented pattern, not executed here). No micro-joints: its arcs and merged lines
//! are not split. The controller's kerf compensation (`kerf run --kerf-in-control`): `CUT3DC`
//! (the offset at right angles to the path tangent and the tool orientation, as kerf's own)
//! with `G450` (circles at outside corners), and per cut `OFFN=<half kerf>` with `G41` or `G42`
//! before the lead-in's first move, `G40` and `OFFN=0` after the beam is off, `CUT2D` at the
//! end (written to Siemens' documented pattern, not executed here).

use kerf_kinematics::Axes;
use nalgebra::{Point3, Vector3};

use super::super::writer::Rules;
use super::super::writer::{feed_number, Writer};
use super::super::{CutterCompensation, LaserPower, ProcessCodes};
use crate::block::{Block, Geometry};

/// The Sinumerik-style dialect.
pub(in crate::output) struct Sinumerik;

impl Rules for Sinumerik {
    fn name(&self) -> &'static str {
        "sinumerik"
    }

    fn joins_poses_only(&self) -> bool {
        false
    }

    fn describe(&self, _n: [&str; 5]) -> (String, String, &'static str) {
        (
            "kerf Sinumerik-style program: TRAORI, tool tip X Y Z and orientation vector A3 B3 C3 in workpiece coordinates".to_string(),
            format!(
                "feed: G94, F in mm/min of the tool tip (TRAORI), the block's mean planned speed;\nfeed: rapids G0 (RTLION) in exact stop G60, split so that the tip follows kerf's traverse (a straight move of the machine's axes) within {} mm; each piece stops, so a split rapid takes longer than planned",
                crate::RAPID_TCP_TOLERANCE_MM
            ),
            "arcs as CIP through the intermediate point",
        )
    }

    fn units_word(&self) -> &'static str {
        "G71"
    }

    fn preamble(&self, w: &mut Writer<'_>) {
        let o = w.opts;
        w.line("G17 G71 G90 G94 G40");
        w.line("G54");
        w.line("SOFT");
        let ctol = o.blend_tolerance_mm / 2.0;
        match o.pivot_length_mm.filter(|l| l.is_finite() && *l > 0.0) {
            Some(l) => {
                let otol = (ctol / l).to_degrees();
                w.line(&format!("CTOL={ctol} OTOL={otol:.6}"));
            }
            None => w.line(&format!("CTOL={}", o.blend_tolerance_mm)),
        }
        w.line("TRAORI");
        w.line("ORIWKS");
        w.line("ORIVECT");
        if compensating(w) {
            // 3D radius compensation at right angles to the path and the tool orientation;
            // outside corners rounded with circles, as kerf's own offset.
            w.line("CUT3DC");
            w.line("G450");
        }
        // G0 interpolated along the tip's line (not axis by axis): each rapid piece below runs
        // as written.
        w.line("RTLION");
        w.line("G60");
        if w.power().is_some() {
            w.line("ID=1 WHENEVER TRUE DO SYNFCT(1,$A_OUTA[1],$AC_VACTW)");
        }
    }

    fn power_header(&self, w: &mut Writer<'_>) {
        w.comment(
            "power: FCTDEF[1, floor, 100, 0, % per mm/min] on $AC_VACTW by synchronized action ID=1",
        );
    }

    /// A rapid under `TRAORI` moves the tip straight (`RTLION`); kerf's traverse is checked
    /// (and planned) as a straight move of the machine's axes, so it is split into pieces
    /// whose tips follow that move within [`crate::RAPID_TCP_TOLERANCE_MM`], as the
    /// tool-tip LinuxCNC dialect's ([`Writer::tip_rapid`]). Under `G60` each piece stops
    /// (the plan has one rest-to-rest move: the header says so), and within a piece the
    /// controller turns the orientation on a great circle (`ORIVECT`), not the rotary axes
    /// linearly: the tip follows within the tolerance, the head within about its distance
    /// from the tip times the square of the piece's turn.
    fn rapid(&self, w: &mut Writer<'_>, p: Point3<f64>, q: Axes, u: Vector3<f64>) {
        let model = w.model;
        w.tip_rapid("G0", p, q, |w, tip, a| {
            // The last piece's orientation is the caller's own `u` (exactly the pose's).
            let axis = if a == &q {
                u
            } else {
                model.tool_axis(a[3], a[4])
            };
            tip_words(w, tip, &axis)
        });
    }

    fn dwell(&self, s: f64) -> String {
        format!("G4 F{s}")
    }

    fn blend_on(&self, w: &mut Writer<'_>) {
        w.line("G642");
    }

    fn descent(
        &self,
        w: &mut Writer<'_>,
        _b: &Block,
        start: Point3<f64>,
        u: Vector3<f64>,
        _t: f64,
        _h: f64,
    ) {
        let f = format!("{:.1}", w.opts.feed_mm_per_min);
        let l = format!("G1 {} F{f}", tip_words(w, &start, &u));
        w.line(&l);
        w.last_f = Some(f);
    }

    fn blend_off(&self, w: &mut Writer<'_>) {
        w.line("G60");
    }

    fn cut(&self, w: &mut Writer<'_>, b: &Block, t: f64) {
        let p = b.end_tip();
        let u = b.end_tool_axis;
        let mut l = match &b.geometry {
            Geometry::Arc(a) => format!(
                "CIP X{} Y{} Z{} I1={} J1={} K1={} A3={} B3={} C3={}",
                w.num(p.x),
                w.num(p.y),
                w.num(p.z),
                w.num(a.mid.x),
                w.num(a.mid.y),
                w.num(a.mid.z),
                w.num(u.x),
                w.num(u.y),
                w.num(u.z)
            ),
            _ => format!("G1 {}", tip_words(w, &p, &u)),
        };
        if !matches!(b.geometry, Geometry::Turn { .. }) {
            let f = format!("{:.1}", b.length() / t * 60.0);
            if w.last_f.as_deref() != Some(f.as_str()) {
                l.push_str(" F");
                l.push_str(&f);
                w.last_f = Some(f);
            }
        }
        w.line(&l);
    }

    fn pierce_power(&self, w: &mut Writer<'_>, power: &LaserPower) {
        let pierce = Writer::pierce_number(power);
        w.line(&format!("FCTDEF(1,{pierce},{pierce},{pierce},0)"));
    }

    fn cut_power(&self, w: &mut Writer<'_>, power: &LaserPower) {
        let floor = w.floor_number(power);
        let k = feed_number(power.per_mm_s(w.factor) / 60.0);
        w.line(&format!("FCTDEF(1,{floor},100,0,{k})"));
    }

    fn power_off(&self, w: &mut Writer<'_>) {
        w.line("CANCEL(1)");
    }

    fn joint_codes(
        &self,
        _process: &ProcessCodes,
    ) -> std::result::Result<(Vec<String>, Vec<String>), &'static str> {
        Err("micro-joints are written for the linuxcnc and generic dialects (the Sinumerik dialect's arcs and merged lines are not split)")
    }

    fn controller_compensation(&self) -> bool {
        true
    }

    /// `OFFN=<half kerf>` and `G41` (left) or `G42` (right): the programmed contour offset
    /// on top of the active tool's radius, which must be 0 for a laser (the header says so).
    /// The compensation builds up over the next move, the lead-in's first.
    fn compensation_on(&self, c: &CutterCompensation) -> Vec<String> {
        let g = if c.left { "G41" } else { "G42" };
        vec![
            format!("OFFN={}", feed_number(0.5 * c.kerf_width_mm)),
            g.to_string(),
        ]
    }

    /// The half kerf is `OFFN`, so an active tool offset `D` of radius 0 (`$TC_DP6` plus the
    /// wear `$TC_DP15`) is needed, and `CUT3DC` needs Siemens' 3D tool radius compensation
    /// option.
    fn compensation_words(&self, kerf_width_mm: f64) -> String {
        format!(
            "CUT3DC G41/G42 OFFN={} (active D radius 0; 3D TRC option)",
            0.5 * kerf_width_mm
        )
    }

    /// `G40` and `OFFN=0` after the beam's off codes: the control leaves the compensated path
    /// on the next move (the retract), which must not cut.
    fn compensation_off(&self) -> (Vec<String>, bool) {
        (vec!["G40".to_string(), "OFFN=0".to_string()], false)
    }

    fn footer(&self, w: &mut Writer<'_>) {
        if compensating(w) {
            w.line("CUT2D");
        }
        w.line("TRAFOOF");
        w.line("M30");
    }
}

/// True where some path of the program is compensated by the controller.
fn compensating(w: &Writer<'_>) -> bool {
    w.opts.cutter_compensation.iter().any(Option::is_some)
}

/// `X Y Z A3= B3= C3=`: the tip and the orientation vector.
fn tip_words(w: &Writer<'_>, p: &Point3<f64>, u: &Vector3<f64>) -> String {
    format!(
        "X{} Y{} Z{} A3={} B3={} C3={}",
        w.num(p.x),
        w.num(p.y),
        w.num(p.z),
        w.num(u.x),
        w.num(u.y),
        w.num(u.z)
    )
}
