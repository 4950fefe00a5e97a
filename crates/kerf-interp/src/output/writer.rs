//! The writer of one program and what a G-code dialect decides. The writer ([`Writer`]) holds
//! what every dialect shares: the header, the framing of every cut (a rapid to the pierce
//! point, the beam on, the dwell, the descent, the cut, the beam off), number formatting, the
//! power's bookkeeping and the pieces a raw-axis block is written in; it asks the dialect's
//! [`Rules`] for everything else. Each dialect is one file under `dialects/` implementing
//! [`Rules`], registered in [`Dialect::rules`](super::Dialect) (the one `match` on the
//! dialect). The trait and the writer live in one module because each names the other (the
//! writer calls the rules, the rules write through the writer).

use kerf_kinematics::Axes;
use nalgebra::{Point3, Vector3};

use crate::block::{Block, Geometry};
use crate::chord::max_step;
use crate::error::Result;
use crate::model::AxisModel;

use super::power::power_number;
use super::{comment_text, ChordTerm, GcodeOptions, LaserPower, ProcessCodes};

/// The relative change of a commanded power (or LinuxCNC's power scale) below which the
/// writer does not write it again: 0.5 %, a tenth of what the power check allows.
pub(super) const POWER_STEP: f64 = 0.005;

/// How far (mm) the tip of a tool-tip dialect's rapid (`linuxcnc-tcp`, `fanuc`, `heidenhain`,
/// `sinumerik`) may run from
/// kerf's joint-space traverse at the middle of each `G0`: LinuxCNC (and Fanuc, by a machine
/// parameter) moves the tip on a straight line between the `G0` ends (with the rotary axes
/// linear, as in joint space), so a traverse is split until each
/// piece's tip chord is this close to the joint-space path at its middle. For fixed rotary axes
/// the head is rigid with the tip, so the whole head runs within it of the checked traverse
/// (to second order between the middles).
pub const RAPID_TCP_TOLERANCE_MM: f64 = 0.1;

/// The most pieces a rapid is split into (a bound that rounding cannot defeat: the split
/// doubles from one piece and stops here). A rapid that needs more (many turns of C far from
/// the axis) is refused ([`crate::InterpError::RapidTooCurved`]), never written farther from
/// its traverse than the header says.
pub const RAPID_TCP_MAX_PIECES: usize = 4096;

/// The most a rotary axis turns in one piece of a tool-tip rapid, degrees, before the
/// middle-distance test: a piece that turns C by whole turns has its middle on its chord (the
/// tip comes back), so the test alone would pass a two-turn rapid as one straight `G0`; on a
/// piece of at most 10 degrees the tip's path is near a circular arc whose largest distance
/// from its chord is at its middle.
pub const RAPID_TCP_MAX_STEP_DEG: f64 = 10.0;

/// The state of one program being written.
pub(super) struct Writer<'a> {
    pub(super) model: &'a dyn AxisModel,
    pub(super) rules: &'static dyn Rules,
    pub(super) opts: &'a GcodeOptions,
    pub(super) process: ProcessCodes,
    pub(super) names: [&'a str; 5],
    pub(super) d: usize,
    pub(super) s: String,
    /// The numbers last written as the controller reads them, for feed and zero-move
    /// decisions: the axis words (raw-axis dialects), or the tip's `X Y Z` and the rotary axes
    /// (the tool-tip dialects; Sinumerik keeps the axes).
    pub(super) last: Option<Axes>,
    pub(super) in_cut: bool,
    /// True while the controller's cutter compensation is on ([`Rules::compensation_on`]
    /// written).
    pub(super) compensating: bool,
    /// The last `F` written (Sinumerik, modal).
    pub(super) last_f: Option<String>,
    /// The last power value written in this cut (LinuxCNC's scale `E0`, an `S`).
    pub(super) last_power: Option<f64>,
    /// The power factor of the path being cut (a small hole's; 1 otherwise).
    pub(super) factor: f64,
    /// LinuxCNC's rotary coefficients last written (`E2`..`E7`, mm per degree).
    pub(super) coeffs: [f64; 6],
    /// A LinuxCNC cutting line whose rotary axes stand still, held back (with its newline) so
    /// that the coefficients of a rotating block after it can be written before it: the
    /// controller's blend starts turning the rotary axes before the next block's synchronized
    /// outputs fire, and while the held block runs the coefficients do not count.
    pub(super) held: Option<String>,
    /// The lines that switch the beam off and on again over a micro-joint (synchronized with
    /// motion), when the program has micro-joints.
    pub(super) joint_codes: Option<(Vec<String>, Vec<String>)>,
    /// The micro-joints of the path being cut (mm of tip travel from its first block).
    pub(super) joints: Vec<[f64; 2]>,
    /// The tip travel of the path being cut so far, mm.
    pub(super) path_s: f64,
    /// The header lines the dialect's [`Rules::machine_lines`] gave (what the controller must
    /// be set up with).
    pub(super) machine_lines: Vec<String>,
    /// The machine axes where the last move ended (the tool-tip dialects: the start of the
    /// next rapid's joint-space path).
    pub(super) last_axes: Option<Axes>,
    /// The largest distance (mm) of a tool-tip rapid's piece from its joint-space traverse,
    /// where [`RAPID_TCP_MAX_PIECES`] were not enough: the program is refused.
    pub(super) rapid_too_curved: Option<f64>,
}

impl<'a> Writer<'a> {
    /// A writer of `opts.dialect`'s program for `model`.
    pub(super) fn new(
        model: &'a dyn AxisModel,
        opts: &'a GcodeOptions,
        process: ProcessCodes,
        joint_codes: Option<(Vec<String>, Vec<String>)>,
        machine_lines: Vec<String>,
    ) -> Self {
        Self {
            model,
            rules: opts.dialect.rules(),
            opts,
            process,
            names: model.axis_names(),
            d: opts.decimals.min(opts.dialect.rules().max_decimals()),
            s: String::new(),
            last: None,
            in_cut: false,
            compensating: false,
            last_f: None,
            last_power: None,
            factor: 1.0,
            coeffs: [0.0; 6],
            held: None,
            joint_codes,
            joints: Vec::new(),
            path_s: 0.0,
            machine_lines,
            last_axes: None,
            rapid_too_curved: None,
        }
    }

    pub(super) fn line(&mut self, l: &str) {
        self.release_held();
        self.s.push_str(l.trim_end());
        self.s.push('\n');
    }

    /// Writes the line held back, if any (see [`Writer::held`]).
    fn release_held(&mut self) {
        if let Some(h) = self.held.take() {
            self.s.push_str(&h);
        }
    }

    /// Holds `l` back (see [`Writer::held`]), writing the line held before.
    pub(super) fn hold(&mut self, mut l: String) {
        self.release_held();
        l.push('\n');
        self.held = Some(l);
    }

    /// The program text, every held line written.
    pub(super) fn finish(mut self) -> String {
        self.release_held();
        self.s
    }

    pub(super) fn comment(&mut self, text: &str) {
        let l = self.opts.dialect.comment(text);
        self.line(&l);
    }

    /// A coordinate as written (no `-0`).
    pub(super) fn num(&self, v: f64) -> String {
        let t = format!("{:.*}", self.d, v);
        match t.strip_prefix('-') {
            Some(rest) if rest.bytes().all(|c| c == b'0' || c == b'.') => rest.to_string(),
            _ => t,
        }
    }

    /// Axis values rounded as the program writes them.
    pub(super) fn printed(&self, q: &Axes) -> Axes {
        q.map(|v| self.num(v).parse().unwrap_or(v))
    }

    /// The move to `q` (axes, or the tip and the rotary axes) as printed and the position it
    /// starts from (the last printed, or `q`'s where nothing was written yet): `None` where the
    /// printed words do not change.
    pub(super) fn moved(&self, q: &Axes) -> Option<(Axes, Axes)> {
        let qp = self.printed(q);
        let prev = self.last.unwrap_or(qp);
        (prev != qp).then_some((qp, prev))
    }

    pub(super) fn axis_words(&self, q: &Axes) -> String {
        let n = &self.names;
        format!(
            "{}{} {}{} {}{} {}{} {}{}",
            n[0],
            self.num(q[0]),
            n[1],
            self.num(q[1]),
            n[2],
            self.num(q[2]),
            n[3],
            self.num(q[3]),
            n[4],
            self.num(q[4])
        )
    }

    pub(super) fn header(&mut self, blocks: &[Block]) {
        let o = self.opts;
        let counts = crate::fit::BlockCounts::of(blocks);
        let (title, feed, arcs_as) = self.rules.describe(self.names);
        for l in self.rules.opening() {
            self.line(l);
        }
        self.comment(&title);
        let machine = format!("machine: {}", comment_text(self.model.name()));
        self.comment(&machine);
        for l in self.machine_lines.clone() {
            self.comment(&l);
        }
        if let Some(src) = &o.source {
            self.comment(&format!("source: {}", comment_text(src)));
        }
        for line in &o.header {
            self.comment(&comment_text(line));
        }
        let unit = self.rules.units_word();
        self.comment(&format!("units: mm ({unit}), degrees, seconds"));
        for part in feed.split('\n') {
            self.comment(part);
        }
        let terms: Vec<String> = o
            .budget()
            .iter()
            .map(|(k, v)| match v {
                Some(v) => format!("{k} {v}"),
                None => format!("{k} unknown"),
            })
            .collect();
        let mut notes = Vec::new();
        match o.chord_term {
            ChordTerm::Certified(_) => {}
            ChordTerm::Claimed(_) => notes.push(
                "the chord term is the toolpath file's claim, not verified by kerf: kerf gcode --curves certifies it",
            ),
            ChordTerm::Unknown => {
                notes.push("the chord term is unknown: the input records no certified chord tolerance")
            }
        }
        if o.linearization_tolerance_mm.is_none() {
            notes.push("the axes file does not record the linearization tolerance");
        }
        let qualifier = if notes.is_empty() {
            ""
        } else {
            " (the known terms)"
        };
        self.comment(&format!(
            "tolerance budget mm: {} = {}{qualifier}",
            terms.join(" + "),
            kerf_io::decimal(o.budget_total(), 12)
        ));
        for note in notes {
            self.comment(&format!("tolerance budget: {note}"));
        }
        self.comment(&format!(
            "blocks: {} lines, {} arcs, {} turns, {arcs_as}",
            counts.lines, counts.arcs, counts.turns
        ));
        let p = self.process.clone();
        let pm = format!(
            "process: beam on {}; beam off {};",
            comment_text(&p.beam_on.join(" / ")),
            comment_text(&p.beam_off.join(" / ")),
        );
        self.comment(&pm);
        let pm = format!(
            "process: pierce {} mm above the cut start along the tool axis, dwell {} s, descent at {} mm/min",
            p.pierce_standoff, p.pierce_dwell_s, o.feed_mm_per_min
        );
        self.comment(&pm);
        match (self.opts.power, self.rules.power_refusal()) {
            (None, _) => self.comment(
                "power: not commanded (no technology): the beam is switched on and off only",
            ),
            (Some(p), Some(why)) => self.comment(&format!(
                "power: the technology's {} % at {} mm/min is not commanded: {why}",
                p.cut_percent, p.reference_feed_mm_per_min
            )),
            (Some(p), None) => {
                self.comment(&format!(
                    "power: {} % at {} mm/min of the tool tip, following the tip speed, floor {} %, pierce {} %",
                    p.cut_percent, p.reference_feed_mm_per_min, p.min_percent, p.pierce_percent
                ));
                self.rules.power_header(self);
            }
        }
        self.rules.preamble(self);
        // The beam is off before the first move, whatever state the controller was left in.
        for l in self.process.beam_off.clone() {
            self.line(&l);
        }
    }

    /// A rapid to the axes `q` (tip `p`, tool axis `u`).
    pub(super) fn rapid(&mut self, p: nalgebra::Point3<f64>, q: Axes, u: nalgebra::Vector3<f64>) {
        self.rules.rapid(self, p, q, u);
    }

    /// Rapid to the pierce point of the cut starting with `b`, beam on, dwell, descent.
    pub(super) fn start_cut(&mut self, b: &Block) {
        let (pierce, qp, u) = pierce_point(self.model, &self.process, b);
        let start = b.start_tip();
        let h = self.process.pierce_standoff;
        self.rapid(pierce, qp, u);
        if let Some(p) = self.power() {
            self.rules.pierce_power(self, &p);
            self.last_power = None;
        }
        for l in self.process.beam_on.clone() {
            let l = self.rules.pierce_beam_on(l);
            self.line(&l);
        }
        let dwell = self.process.pierce_dwell_s;
        if dwell > 0.0 {
            let l = self.rules.dwell(dwell);
            self.line(&l);
        }
        self.rules.blend_on(self);
        self.in_cut = true;
        if let Some(p) = self.power() {
            self.rules.cut_power(self, &p);
        }
        if h > 0.0 {
            let t = self.process.descent_s(self.opts.feed_mm_per_min);
            self.rules.descent(self, b, start, u, t, h);
            self.last_axes = Some(b.start_axes);
        }
    }

    /// The beam off (`on` false) or on again at a micro-joint's end, synchronized with the
    /// next move.
    fn joint_switch(&mut self, on: bool) {
        let Some((off_lines, on_lines)) = self.joint_codes.clone() else {
            return;
        };
        for l in if on { on_lines } else { off_lines } {
            self.line(&l);
        }
    }

    /// The controller's kerf compensation from the next move (the lead-in's first, the entry
    /// move), until [`Writer::end_cut`].
    pub(super) fn compensation_on(&mut self, c: &super::CutterCompensation) {
        for l in self.rules.compensation_on(c) {
            self.line(&l);
        }
        self.compensating = true;
    }

    pub(super) fn end_cut(&mut self) {
        // Off before or after the beam, as the dialect says ([`Rules::compensation_off`]).
        let (off, before_beam) = if self.compensating {
            self.compensating = false;
            self.rules.compensation_off()
        } else {
            (Vec::new(), true)
        };
        if before_beam {
            for l in &off {
                self.line(l);
            }
        }
        for l in self.process.beam_off.clone() {
            self.line(&l);
        }
        if !before_beam {
            for l in &off {
                self.line(l);
            }
        }
        self.rules.blend_off(self);
        self.in_cut = false;
    }

    /// The cutting block `b`, taking `t` seconds; the next rapid's split starts from its end
    /// ([`Writer::tip_rapid`]), whatever the dialect wrote.
    pub(super) fn cut(&mut self, b: &Block, t: f64) {
        self.rules.cut(self, b, t);
        self.last_axes = Some(b.end_axes);
    }

    /// A block of a dialect that joins poses with `G1` lines, in the pieces it is written as:
    /// arcs become chords within the chord tolerance (eq 18), the block's time shared in
    /// proportion to the path parameter; the block is split where a micro-joint starts or ends
    /// and the beam switched there. `step(writer, s, q, dt, tip_mm)` writes the move to path
    /// parameter `s` (axes `q`) taking `dt` seconds over `tip_mm` of tip travel.
    pub(super) fn block_pieces(
        &mut self,
        b: &Block,
        t: f64,
        mut step: impl FnMut(&mut Self, f64, Axes, f64, f64),
    ) {
        let mut ends = Vec::new();
        if let Geometry::Arc(a) = &b.geometry {
            let k = (b.length() / max_step(a.radius, self.opts.chord_tolerance_mm))
                .ceil()
                .max(1.0) as usize;
            for i in 1..k {
                let s = b.length() * i as f64 / k as f64;
                ends.push((s, b.axes_at(self.model, s)));
            }
        }
        ends.push((b.length(), b.end_axes));
        // A turn's parameter is degrees; its tip stands still.
        let turn = matches!(b.geometry, Geometry::Turn { .. });
        // Micro-joint ends inside the block: split there, the beam switched after.
        let mut switches: Vec<(f64, bool)> = Vec::new();
        if !turn && b.length() > 0.0 {
            for j in &self.joints {
                for (edge, on) in [(j[0], false), (j[1], true)] {
                    let s = edge - self.path_s;
                    if s > 0.0 && s <= b.length() {
                        switches.push((s, on));
                    }
                }
            }
        }
        for &(s, _) in &switches {
            if s < b.length() {
                ends.push((s, b.axes_at(self.model, s)));
            }
        }
        ends.sort_by(|a, b| a.0.total_cmp(&b.0));
        ends.dedup_by(|a, b| a.0 == b.0);
        let mut s0 = 0.0;
        for (s, q) in ends {
            let share = if b.length() > 0.0 {
                (s - s0) / b.length()
            } else {
                1.0
            };
            step(self, s, q, t * share, if turn { 0.0 } else { s - s0 });
            for &(_, on) in switches.iter().filter(|w| w.0 == s) {
                self.joint_switch(on);
            }
            s0 = s;
        }
        if !turn {
            self.path_s += b.length();
        }
    }

    /// A powered LinuxCNC move from the axes `a` to `b` (as printed) taking `t` seconds, as
    /// [`super::power::pieces`] splits it (up to [`super::power::MAX_POWER_PIECES`] pieces of
    /// the same motion): before each piece its rotary coefficients where they changed, then the
    /// line `line(writer, f, dt)` that moves to fraction `f` of the move (1 for the last piece)
    /// in `dt` seconds; a move whose rotary axes stand still is held back (see
    /// [`Writer::held`]).
    pub(super) fn powered_pieces(
        &mut self,
        a: &Axes,
        b: &Axes,
        line: impl Fn(&Self, f64, f64) -> String,
        t: f64,
    ) {
        let pieces = super::power::pieces(self.model, a, b);
        let at = |f: f64| a.lerp(b, f);
        let mut f0 = 0.0;
        for (i, &(f1, coeffs)) in pieces.iter().enumerate() {
            let f1 = if i + 1 == pieces.len() { 1.0 } else { f1 };
            let (qa, qb) = (at(f0), if f1 == 1.0 { *b } else { self.printed(&at(f1)) });
            self.write_coefficients(&qa, &qb, coeffs);
            let l = line(self, f1, t * (f1 - f0));
            if a[3] == b[3] && a[4] == b[4] {
                self.hold(l);
            } else {
                self.line(&l);
            }
            f0 = f1;
        }
    }

    /// LinuxCNC's rotary coefficients `coeffs` for the piece from `a` to `b`, written where
    /// the last ones written would misjudge its tip travel by more than [`POWER_STEP`].
    fn write_coefficients(&mut self, a: &Axes, b: &Axes, coeffs: [f64; 6]) {
        let d: [f64; 5] = std::array::from_fn(|k| b[k] - a[k]);
        let (new, old) = (
            super::power::tip_travel(&d, &coeffs),
            super::power::tip_travel(&d, &self.coeffs),
        );
        if (new - old).abs() > POWER_STEP * new.max(1e-9) {
            // Before a held line (a block whose rotary axes stand still), so that they are
            // set when the controller's blend into this block starts turning them.
            for (j, v) in coeffs.iter().enumerate() {
                self.s
                    .push_str(&format!("M67 E{} Q{}\n", j + 2, coeff_number(*v)));
            }
            self.coeffs = coeffs;
        }
    }

    /// True (and `v` remembered) when `v` differs from the last power value written in this
    /// cut by more than [`POWER_STEP`] of it.
    pub(super) fn power_changed(&mut self, v: f64) -> bool {
        let changed = self
            .last_power
            .is_none_or(|last| (v - last).abs() > POWER_STEP * last.abs().max(1e-9));
        if changed {
            self.last_power = Some(v);
        }
        changed
    }

    /// The planned power at `tip_mm` of tip travel in `t` seconds as an ` S` word, where it
    /// changed by more than [`POWER_STEP`] (the dialects that command power by `S`); empty
    /// outside a cut or without power.
    pub(super) fn s_word(&mut self, tip_mm: f64, t: f64) -> String {
        match (self.power(), self.in_cut) {
            (Some(power), true) => {
                let p = power.at_speed(tip_mm / t * 60.0, self.factor);
                if self.power_changed(p) {
                    format!(" S{}", power_number(p))
                } else {
                    String::new()
                }
            }
            _ => String::new(),
        }
    }

    /// A rapid of a tool-tip dialect to the tip `p` with the axes `q`: LinuxCNC, Fanuc,
    /// HEIDENHAIN and Sinumerik (`RTLION`) move the tip straight between `G0` ends (Fanuc may
    /// move the axes linearly, by a machine parameter), so the rapid is split along kerf's checked joint-space traverse from the
    /// last axes ([`rapid_pieces`]), each piece `<g0> <words(tip, axes)>`,
    /// the last ending exactly at `p`.
    pub(super) fn tip_rapid(
        &mut self,
        g0: &str,
        p: nalgebra::Point3<f64>,
        q: Axes,
        words: impl Fn(&Self, &nalgebra::Point3<f64>, &Axes) -> String,
    ) {
        let pieces = match self.last_axes {
            Some(from) => {
                let (pieces, worst) = rapid_pieces(self.model, &from, &q);
                // False for NaN too (an unusable model): refused.
                let within = worst <= RAPID_TCP_TOLERANCE_MM;
                if !within {
                    let d = if worst.is_nan() { f64::INFINITY } else { worst };
                    self.rapid_too_curved = Some(self.rapid_too_curved.map_or(d, |w| w.max(d)));
                }
                pieces
            }
            None => vec![q],
        };
        let n = pieces.len();
        for (i, a) in pieces.into_iter().enumerate() {
            let tip = if i + 1 == n { p } else { self.model.tip(&a) };
            let l = format!("{g0} {}", words(self, &tip, &a));
            self.line(&l);
        }
        self.last = Some(self.printed(&Axes::new(p.x, p.y, p.z, q.tilt, q.c)));
        self.last_axes = Some(q);
    }

    /// The power the program commands: the options' where the dialect can command it
    /// ([`Rules::power_refusal`]).
    pub(super) fn power(&self) -> Option<super::LaserPower> {
        self.opts
            .power
            .filter(|_| self.rules.power_refusal().is_none())
    }

    /// The pierce power's number (percent, at most 100).
    pub(super) fn pierce_number(power: &super::LaserPower) -> String {
        power_number(power.pierce_percent.min(100.0))
    }

    /// The cut's floor (percent): the power never drops below it while cutting.
    pub(super) fn floor_number(&self, power: &super::LaserPower) -> String {
        power_number(power.min_percent.min(power.cut_percent * self.factor))
    }
}

/// `M<m> P<n>` (LinuxCNC's digital outputs, `m` in 62..=65): `(m, n)`.
pub(super) fn digital_output(line: &str) -> Option<(u32, u32)> {
    let mut words = line.split_whitespace();
    let m = words.next()?.strip_prefix('M')?.parse().ok()?;
    let p = words.next()?.strip_prefix('P')?.parse().ok()?;
    (words.next().is_none() && (62..=65).contains(&m)).then_some((m, p))
}

/// The ends of the `G0` pieces of a rapid from the axes `from` to `to` (the last is `to`):
/// `2^k` equal pieces in joint space, the fewest (at most [`RAPID_TCP_MAX_PIECES`]) that turn
/// no rotary axis by more than [`RAPID_TCP_MAX_STEP_DEG`] and whose tip chords lie within
/// [`RAPID_TCP_TOLERANCE_MM`] of the joint-space path's tip at each piece's middle; with the
/// largest middle distance of the pieces returned (above the tolerance, or infinite, only when
/// [`RAPID_TCP_MAX_PIECES`] were not enough).
fn rapid_pieces(model: &dyn AxisModel, from: &Axes, to: &Axes) -> (Vec<Axes>, f64) {
    let at = |f: f64| from.lerp(to, f);
    let turn = (to[3] - from[3]).abs().max((to[4] - from[4]).abs());
    let steps = (turn / RAPID_TCP_MAX_STEP_DEG).ceil();
    // False for NaN too.
    let fits = steps <= RAPID_TCP_MAX_PIECES as f64;
    if !fits {
        return (vec![*to], f64::INFINITY);
    }
    let mut n = (steps as usize).max(1).next_power_of_two();
    let worst = loop {
        let worst = (0..n)
            .map(|i| {
                let (a, b) = (i as f64 / n as f64, (i + 1) as f64 / n as f64);
                let (ta, tb) = (model.tip(&at(a)), model.tip(&at(b)));
                let mid = model.tip(&at((a + b) / 2.0));
                (nalgebra::center(&ta, &tb) - mid).norm()
            })
            // NaN wins (f64::max would drop it).
            .fold(0.0, |a: f64, b| {
                if a.is_nan() || b.is_nan() {
                    f64::NAN
                } else {
                    a.max(b)
                }
            });
        // NaN (an unusable model) stops the split too; the caller refuses it.
        let over = worst > RAPID_TCP_TOLERANCE_MM;
        if !over || n >= RAPID_TCP_MAX_PIECES {
            break worst;
        }
        n *= 2;
    };
    let pieces = (1..=n)
        .map(|i| if i == n { *to } else { at(i as f64 / n as f64) })
        .collect();
    (pieces, worst)
}

/// The feed of a move from `prev` to `now` (printed `X Y Z` and rotary axes) taking `t`
/// seconds by the RS274/NGC rule: mm/min of the `X Y Z` motion, or deg/min of the rotary
/// motion where `X Y Z` stand.
pub(super) fn rs274_feed(prev: &Axes, now: &Axes, t: f64) -> f64 {
    let d: [f64; 5] = std::array::from_fn(|k| now[k] - prev[k]);
    let lin = (d[0] * d[0] + d[1] * d[1] + d[2] * d[2]).sqrt();
    let len = if lin > 0.0 {
        lin
    } else {
        (d[3] * d[3] + d[4] * d[4]).sqrt()
    };
    len / t * 60.0
}

/// A rotary coefficient as written (mm per degree): nine decimals, enough that the rounding
/// moves a tip speed by less than 1e-6 of a 100 deg/s rotation's.
fn coeff_number(v: f64) -> String {
    let t = format!("{v:.9}");
    match t.strip_prefix('-') {
        Some(rest) if rest.bytes().all(|c| c == b'0' || c == b'.') => rest.to_string(),
        _ => t,
    }
}

/// A feed value with six significant digits in plain decimal notation (controllers read no
/// exponents), never written as 0.
pub(super) fn feed_number(f: f64) -> String {
    let f = if f.is_finite() { f.max(1e-9) } else { 1e9 };
    let mag = f.log10().floor() as i32;
    let decimals = (5 - mag).clamp(0, 12) as usize;
    format!("{f:.decimals$}")
}

/// The end of the retract after the program's last cut, `b` (along the tool axis at its
/// end, the larger of `pierce_standoff` and [`crate::EXIT_RETRACT_MIN_MM`]): the point, the
/// machine axes there (the end's rotary axes), the tool axis and the retract (mm).
pub(super) fn exit_point<M: AxisModel + ?Sized>(
    model: &M,
    process: &ProcessCodes,
    b: &Block,
) -> (nalgebra::Point3<f64>, Axes, nalgebra::Vector3<f64>, f64) {
    let (tilt, c) = (b.end_axes.tilt, b.end_axes.c);
    let u = model.tool_axis(tilt, c);
    let h = process.pierce_standoff.max(crate::EXIT_RETRACT_MIN_MM);
    let p = b.end_tip() + u * h;
    let lin = model.linear_axes(&p, tilt, c);
    (p, Axes::new(lin[0], lin[1], lin[2], tilt, c), u, h)
}

/// The pierce point of the cut starting with `b` (`pierce_standoff` above its start along the
/// tool axis), the machine axes there (the start's rotary axes) and the tool axis.
pub(super) fn pierce_point<M: AxisModel + ?Sized>(
    model: &M,
    process: &ProcessCodes,
    b: &Block,
) -> (nalgebra::Point3<f64>, Axes, nalgebra::Vector3<f64>) {
    let (tilt, c) = (b.start_axes.tilt, b.start_axes.c);
    let u = model.tool_axis(tilt, c);
    let h = process.pierce_standoff;
    let pierce = b.start_tip() + u * h;
    let q = if h > 0.0 {
        let lin = model.linear_axes(&pierce, tilt, c);
        Axes::new(lin[0], lin[1], lin[2], tilt, c)
    } else {
        b.start_axes
    };
    (pierce, q, u)
}

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
    fn rapid(&self, w: &mut Writer<'_>, p: Point3<f64>, q: Axes, u: Vector3<f64>);

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

    /// True where the controller's kerf compensation can be written
    /// ([`Rules::compensation_on`]).
    fn controller_compensation(&self) -> bool {
        false
    }

    /// The lines that switch the controller's kerf compensation on for the next move (the
    /// lead-in's first, the controller's entry move): none by default (see
    /// [`Rules::controller_compensation`]).
    fn compensation_on(&self, _c: &super::CutterCompensation) -> Vec<String> {
        Vec::new()
    }

    /// True where the controller's compensation offsets in X and Y only, so that a compensated
    /// cut must stand the beam vertical with the rotary axes still (LinuxCNC's `G41.1`).
    fn compensation_xy_only(&self) -> bool {
        false
    }

    /// How the controller compensates a kerf of `kerf_width_mm`, in the program header's
    /// words: empty where it cannot ([`Rules::controller_compensation`]).
    fn compensation_words(&self, _kerf_width_mm: f64) -> String {
        String::new()
    }

    /// The lines that switch it off at the cut's end, and whether they come before the beam's
    /// off codes (`true`) or after them: `G40` before the beam by default.
    fn compensation_off(&self) -> (Vec<String>, bool) {
        (vec!["G40".to_string()], true)
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

#[cfg(test)]
mod tests {
    use super::*;

    fn trunnion() -> crate::MachineModel {
        let path = concat!(
            env!("CARGO_MANIFEST_DIR"),
            "/../../fixtures/machines/xyzac_trt.json"
        );
        crate::MachineModel::new(kerf_kinematics::Machine::read(path).expect("machine"))
            .expect("model")
    }

    #[test]
    fn rapids_are_split_until_their_tip_follows_the_traverse_or_refused() {
        let m = trunnion();
        // A straight move of the linear axes alone: one piece, on the traverse.
        let (p, worst) = rapid_pieces(
            &m,
            &Axes::default(),
            &Axes::new(100.0, 50.0, 20.0, 0.0, 0.0),
        );
        assert_eq!(p.len(), 1);
        assert!(worst < 1e-9, "{worst}");
        // Half a turn of C with the tip 200 mm from the C axis: the tip's circle, split into
        // pieces of at most 10 degrees and then until every piece's middle is within the
        // tolerance, by the fewest halvings.
        let from = Axes::new(200.0, 0.0, 0.0, 0.0, 0.0);
        let (p, worst) = rapid_pieces(&m, &from, &Axes::new(200.0, 0.0, 0.0, 0.0, 180.0));
        assert!(worst <= RAPID_TCP_TOLERANCE_MM, "{worst}");
        // The tip turns about the C axis through rot_point (3, -2) of xyzac_trt.json.
        let t = m.tip(&from);
        let r = (t.x - 3.0).hypot(t.y + 2.0);
        // An arc of `turn` degrees and radius r in n pieces has its chords' middles
        // r (1 - cos(turn / 2n)) inside it: the fewest n = 2^k with pieces of at most 10
        // degrees and that at most 0.1 mm.
        let need = |turn: f64| {
            (0..20)
                .map(|k| 1usize << k)
                .find(|n| {
                    let piece = turn / *n as f64;
                    piece <= RAPID_TCP_MAX_STEP_DEG
                        && r * (1.0 - (piece.to_radians() / 2.0).cos()) <= 0.1
                })
                .expect("a count")
        };
        assert_eq!(p.len(), need(180.0), "r = {r}");
        // Two whole turns: the tip comes back to its start at the middle too, yet the rapid
        // swings it round twice; pieces of 10 degrees see the circle.
        let (p, worst) = rapid_pieces(&m, &from, &Axes::new(200.0, 0.0, 0.0, 0.0, 720.0));
        assert_eq!(p.len(), need(720.0), "r = {r}");
        assert!(worst <= RAPID_TCP_TOLERANCE_MM, "{worst}");
        // A hundred turns at the same distance: 4096 pieces of 8.8 degrees leave 0.59 mm, more
        // than RAPID_TCP_MAX_PIECES would be needed: the distance left is reported, and the
        // writer refuses the program.
        let (p, worst) = rapid_pieces(&m, &from, &Axes::new(200.0, 0.0, 0.0, 0.0, 36000.0));
        assert_eq!(p.len(), RAPID_TCP_MAX_PIECES);
        assert!(worst > RAPID_TCP_TOLERANCE_MM, "{worst}");
        // Two thousand turns cannot even be cut into 10-degree pieces: refused at once.
        let (_, worst) = rapid_pieces(&m, &from, &Axes::new(200.0, 0.0, 0.0, 0.0, 720000.0));
        assert!(worst.is_infinite());
    }
}
