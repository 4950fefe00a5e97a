//! The writer of one program: blocks, cut framing and feeds, dialect by dialect.

use crate::block::{Block, Geometry};
use crate::chord::max_step;
use crate::model::AxisModel;

use super::power::power_number;
use super::{comment_text, ChordTerm, Dialect, GcodeOptions, ProcessCodes};

/// The relative change of a commanded power (or LinuxCNC's power scale) below which the
/// writer does not write it again: 0.5 %, a tenth of what the power check allows.
const POWER_STEP: f64 = 0.005;

/// The state of one program being written.
pub(super) struct Writer<'a, M: AxisModel + ?Sized> {
    pub(super) model: &'a M,
    pub(super) opts: &'a GcodeOptions,
    pub(super) process: ProcessCodes,
    pub(super) names: [&'a str; 5],
    pub(super) d: usize,
    pub(super) s: String,
    /// The numbers last written as the controller reads them, for feed and zero-move
    /// decisions: the axis words (raw-axis dialects), or the tip's `X Y Z` and the rotary axes
    /// (`linuxcnc-tcp`).
    pub(super) last: Option<[f64; 5]>,
    pub(super) in_cut: bool,
    /// True while the controller's cutter compensation is on (`G41.1`/`G42.1` written).
    pub(super) compensating: bool,
    /// The last `F` written (Sinumerik, modal).
    pub(super) last_f: Option<String>,
    /// The last power value written in this cut (LinuxCNC's scale `E0`, the generic `S`).
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
    /// LinuxCNC's kinematics module for the machine ([`Dialect::LinuxcncTcp`] only).
    pub(super) tcp: Option<super::LinuxcncKinematics>,
    /// The machine axes where the last move ended (`linuxcnc-tcp`: the start of the next
    /// rapid's joint-space path).
    pub(super) last_axes: Option<[f64; 5]>,
}

impl<M: AxisModel + ?Sized> Writer<'_, M> {
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
    fn hold(&mut self, mut l: String) {
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
    pub(super) fn printed(&self, q: &[f64; 5]) -> [f64; 5] {
        q.map(|v| self.num(v).parse().unwrap_or(v))
    }

    pub(super) fn axis_words(&self, q: &[f64; 5]) -> String {
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

    pub(super) fn tip_words(
        &self,
        p: &nalgebra::Point3<f64>,
        u: &nalgebra::Vector3<f64>,
    ) -> String {
        format!(
            "X{} Y{} Z{} A3={} B3={} C3={}",
            self.num(p.x),
            self.num(p.y),
            self.num(p.z),
            self.num(u.x),
            self.num(u.y),
            self.num(u.z)
        )
    }

    pub(super) fn header(&mut self, blocks: &[Block]) {
        let o = self.opts;
        let n = self.names;
        let counts = crate::fit::BlockCounts::of(blocks);
        let (title, feed, arcs_as) = match o.dialect {
            Dialect::Linuxcnc => (
                format!(
                    "kerf LinuxCNC program: trivkins machine axes {} {} {} {} {}, no tool-tip control",
                    n[0], n[1], n[2], n[3], n[4]
                ),
                "feed: G93 inverse time on every cutting block, F = 60 / planned block time in s,\nfeed: so the tool tip moves at kerf's planned speed; rapids G0 in exact path G61".to_string(),
                "arcs written as G1 chords",
            ),
            Dialect::Generic => (
                format!(
                    "kerf generic 5-axis program: machine axes {} {} {} {} {}, no tool-tip control",
                    n[0], n[1], n[2], n[3], n[4]
                ),
                format!(
                    "feed: G94, F in mm/min of the combined {} {} {} machine-axis motion, NOT of the tool tip;\nfeed: on blocks without {} {} {} motion F is deg/min of the combined rotary motion (RS274/NGC rule);\nfeed: each F makes its block take kerf's planned time",
                    n[0], n[1], n[2], n[0], n[1], n[2]
                ),
                "arcs written as G1 chords",
            ),
            Dialect::LinuxcncTcp => (
                format!(
                    "kerf LinuxCNC tool-tip program: X Y Z the tool tip in the workpiece frame, {} {} the rotary axes",
                    n[3], n[4]
                ),
                format!(
                    "feed: G94, F in mm/min of the tool tip [the kinematics' world X Y Z], the block's mean planned speed;\nfeed: on blocks where the tip stands F is deg/min of the rotary motion;\nfeed: rapids G0 in exact path G61, split so that the tip follows kerf's joint-space traverse within {} mm",
                    super::RAPID_TCP_TOLERANCE_MM
                ),
                "arcs written as G1 chords",
            ),
            Dialect::Sinumerik => (
                "kerf Sinumerik-style program: TRAORI, tool tip X Y Z and orientation vector A3 B3 C3 in workpiece coordinates".to_string(),
                "feed: G94, F in mm/min of the tool tip (TRAORI), the block's mean planned speed".to_string(),
                "arcs as CIP through the intermediate point",
            ),
        };
        self.comment(&title);
        let machine = format!("machine: {}", comment_text(self.model.name()));
        self.comment(&machine);
        if let Some(k) = self.tcp.clone() {
            self.comment(&format!(
                "kinematics: LinuxCNC [KINS] KINEMATICS = {}, [TRAJ] COORDINATES = {}, its tool-tip kinematics active [switchkins type 0]",
                k.module, k.coordinates
            ));
            for l in k.setp_lines() {
                self.comment(&format!("kinematics: {l}"));
            }
        }
        if let Some(src) = &o.source {
            self.comment(&format!("source: {}", comment_text(src)));
        }
        for line in &o.header {
            self.comment(&comment_text(line));
        }
        let unit = if o.dialect == Dialect::Sinumerik {
            "G71"
        } else {
            "G21"
        };
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
            o.budget_total()
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
        self.power_header();
        match o.dialect {
            Dialect::Linuxcnc => {
                self.line("G17 G21 G40 G49 G54 G80 G90 G94");
                self.line("G93");
                self.line("G61");
            }
            Dialect::LinuxcncTcp => {
                self.line("G17 G21 G40 G49 G54 G80 G90 G94");
                self.line("G61");
            }
            Dialect::Generic => self.line("G17 G21 G40 G90 G94"),
            Dialect::Sinumerik => {
                self.line("G17 G71 G90 G94 G40");
                self.line("G54");
                self.line("SOFT");
                let ctol = o.blend_tolerance_mm / 2.0;
                match o.pivot_length_mm.filter(|l| l.is_finite() && *l > 0.0) {
                    Some(l) => {
                        let otol = (ctol / l).to_degrees();
                        self.line(&format!("CTOL={ctol} OTOL={otol:.6}"));
                    }
                    None => self.line(&format!("CTOL={}", o.blend_tolerance_mm)),
                }
                self.line("TRAORI");
                self.line("ORIWKS");
                self.line("ORIVECT");
                self.line("G60");
                if self.opts.power.is_some() {
                    self.line("ID=1 WHENEVER TRUE DO SYNFCT(1,$A_OUTA[1],$AC_VACTW)");
                }
            }
        }
        // The beam is off before the first move, whatever state the controller was left in.
        for l in self.process.beam_off.clone() {
            self.line(&l);
        }
    }

    /// A rapid to the axes `q` (tip `p`, tool axis `u`).
    pub(super) fn rapid(
        &mut self,
        p: nalgebra::Point3<f64>,
        q: [f64; 5],
        u: nalgebra::Vector3<f64>,
    ) {
        let l = match self.opts.dialect {
            Dialect::Sinumerik => format!("G0 {}", self.tip_words(&p, &u)),
            Dialect::LinuxcncTcp => {
                // LinuxCNC moves the tip straight between G0 ends: pieces along the
                // joint-space traverse kerf checked, the last ending exactly at `p`.
                let pieces = match self.last_axes {
                    Some(from) => super::linuxcnc_tcp::rapid_pieces(self.model, &from, &q),
                    None => vec![q],
                };
                let n = pieces.len();
                for (i, a) in pieces.into_iter().enumerate() {
                    let tip = if i + 1 == n { p } else { self.model.tip(&a) };
                    let l = format!("G0 {}", self.tcp_words(&tip, a[3], a[4]));
                    self.line(&l);
                }
                self.last = Some(self.printed(&[p.x, p.y, p.z, q[3], q[4]]));
                self.last_axes = Some(q);
                return;
            }
            _ => format!("G0 {}", self.axis_words(&q)),
        };
        self.line(&l);
        self.last = Some(self.printed(&q));
        self.last_axes = Some(q);
    }

    /// The words of a `linuxcnc-tcp` position: the tip `X Y Z` and the rotary axes.
    fn tcp_words(&self, tip: &nalgebra::Point3<f64>, tilt: f64, c: f64) -> String {
        let n = &self.names;
        format!(
            "X{} Y{} Z{} {}{} {}{}",
            self.num(tip.x),
            self.num(tip.y),
            self.num(tip.z),
            n[3],
            self.num(tilt),
            n[4],
            self.num(c)
        )
    }

    /// One `linuxcnc-tcp` `G1` to the tip `tip` with the axes `q`, taking `t` seconds: `F` the
    /// tip's speed in mm/min (deg/min of the rotary motion where the printed tip stands, the
    /// RS274/NGC rule); nothing if the printed words do not change.
    fn tcp_move(&mut self, tip: nalgebra::Point3<f64>, q: [f64; 5], t: f64) {
        let now = self.printed(&[tip.x, tip.y, tip.z, q[3], q[4]]);
        let prev = self.last.unwrap_or(now);
        let from = self.last_axes.replace(q);
        if prev == now {
            return;
        }
        let d: [f64; 5] = std::array::from_fn(|k| now[k] - prev[k]);
        let lin = (d[0] * d[0] + d[1] * d[1] + d[2] * d[2]).sqrt();
        let len = if lin > 0.0 {
            lin
        } else {
            (d[3] * d[3] + d[4] * d[4]).sqrt()
        };
        // The feed is the same on every piece: the pieces split the move evenly in time.
        let f = feed_number(len / t * 60.0);
        match (self.opts.power.is_some() && self.in_cut, from) {
            // The controller computes the tip's speed from its joints as for the joint-space
            // dialect (module docs of `power`): the same coefficients, the move in pieces of
            // its own tip line.
            (true, Some(from)) => {
                let words = |w: &Self, f: f64| -> String {
                    let p: [f64; 5] = std::array::from_fn(|k| prev[k] + f * d[k]);
                    w.tcp_words(&nalgebra::Point3::new(p[0], p[1], p[2]), p[3], p[4])
                };
                self.powered_pieces(
                    &self.printed(&from),
                    &self.printed(&q),
                    |w, fr, _| {
                        let end = if fr == 1.0 {
                            w.tcp_words(&tip, q[3], q[4])
                        } else {
                            words(w, fr)
                        };
                        format!("G1 {end} F{f}")
                    },
                    t,
                );
            }
            _ => {
                let l = format!("G1 {} F{f}", self.tcp_words(&tip, q[3], q[4]));
                self.line(&l);
            }
        }
        self.last = Some(now);
    }

    /// Rapid to the pierce point of the cut starting with `b`, beam on, dwell, descent.
    pub(super) fn start_cut(&mut self, b: &Block) {
        let (pierce, qp, u) = pierce_point(self.model, &self.process, b);
        let start = b.start_tip();
        let h = self.process.pierce_standoff;
        self.rapid(pierce, qp, u);
        self.pierce_power();
        for l in self.process.beam_on.clone() {
            // The pierce is lit at once: a synchronized `M62` would wait for the next move and
            // the dwell would run dark.
            let l = match digital_output(&l) {
                Some((62, p)) if self.opts.dialect.linuxcnc() => format!("M64 P{p}"),
                _ => l,
            };
            self.line(&l);
        }
        let dwell = self.process.pierce_dwell_s;
        if dwell > 0.0 {
            let l = match self.opts.dialect {
                Dialect::Sinumerik => format!("G4 F{dwell}"),
                _ => format!("G4 P{dwell}"),
            };
            self.line(&l);
        }
        match self.opts.dialect {
            Dialect::Linuxcnc | Dialect::LinuxcncTcp => {
                let l = format!("G64 P{} Q0", self.opts.blend_tolerance_mm);
                self.line(&l);
            }
            Dialect::Sinumerik => self.line("G642"),
            Dialect::Generic => {}
        }
        self.in_cut = true;
        self.cut_power();
        if h > 0.0 {
            let t = self.process.descent_s(self.opts.feed_mm_per_min);
            match self.opts.dialect {
                Dialect::Sinumerik => {
                    let f = format!("{:.1}", self.opts.feed_mm_per_min);
                    let l = format!("G1 {} F{f}", self.tip_words(&start, &u));
                    self.line(&l);
                    self.last_f = Some(f);
                }
                Dialect::LinuxcncTcp => self.tcp_move(start, b.start_axes, t),
                _ => self.raw_move(b.start_axes, t, h),
            }
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
        let g = if c.left { "G41.1" } else { "G42.1" };
        let l = format!("{g} D{}", feed_number(c.kerf_width_mm));
        self.line(&l);
        self.compensating = true;
    }

    pub(super) fn end_cut(&mut self) {
        // Off before the beam: LinuxCNC sets no output while the compensation is on.
        if self.compensating {
            self.line("G40");
            self.compensating = false;
        }
        for l in self.process.beam_off.clone() {
            self.line(&l);
        }
        match self.opts.dialect {
            Dialect::Linuxcnc | Dialect::LinuxcncTcp => self.line("G61"),
            Dialect::Sinumerik => self.line("G60"),
            Dialect::Generic => {}
        }
        self.in_cut = false;
    }

    /// One `G1` of a raw-axis dialect to `q`, taking `t` seconds while the tip moves
    /// `tip_mm`; nothing if the printed axes do not change. With [`GcodeOptions::power`] the
    /// block's power goes with it (LinuxCNC's scale line before it, the generic `S` on it).
    pub(super) fn raw_move(&mut self, q: [f64; 5], t: f64, tip_mm: f64) {
        let qp = self.printed(&q);
        let prev = self.last.unwrap_or(qp);
        if prev == qp {
            return;
        }
        let lin =
            ((qp[0] - prev[0]).powi(2) + (qp[1] - prev[1]).powi(2) + (qp[2] - prev[2]).powi(2))
                .sqrt();
        let f = match self.opts.dialect {
            Dialect::Linuxcnc => 60.0 / t,
            _ => {
                let rot = ((qp[3] - prev[3]).powi(2) + (qp[4] - prev[4]).powi(2)).sqrt();
                let len = if lin > 0.0 { lin } else { rot };
                len / t * 60.0
            }
        };
        let mut s_word = String::new();
        if let (Some(power), true) = (self.opts.power, self.in_cut) {
            match self.opts.dialect {
                // The controller computes the tip's speed from the joints' (module docs of
                // `power`): the rotary coefficients go with the block where stale ones would
                // misjudge its tip travel by more than POWER_STEP.
                Dialect::Linuxcnc if !self.compensating => {
                    self.powered_pieces(
                        &prev,
                        &qp,
                        |w, f, dt| {
                            let end = if f == 1.0 {
                                q
                            } else {
                                w.printed(&std::array::from_fn(|k| prev[k] + f * (qp[k] - prev[k])))
                            };
                            format!("G1 {} F{}", w.axis_words(&end), feed_number(60.0 / dt))
                        },
                        t,
                    );
                    self.last = Some(qp);
                    self.last_axes = Some(q);
                    return;
                }
                Dialect::Generic => {
                    let p = power.at_speed(tip_mm / t * 60.0, self.factor);
                    if self.power_changed(p) {
                        s_word = format!(" S{}", power_number(p));
                    }
                }
                _ => {}
            }
        }
        let l = format!("G1 {} F{}{s_word}", self.axis_words(&q), feed_number(f));
        self.line(&l);
        self.last = Some(qp);
        self.last_axes = Some(q);
    }

    /// A powered LinuxCNC move from the axes `a` to `b` (as printed) taking `t` seconds, as
    /// [`super::power::pieces`] splits it (up to [`super::power::MAX_POWER_PIECES`] pieces of
    /// the same motion): before each piece its rotary coefficients where they changed, then the
    /// line `line(writer, f, dt)` that moves to fraction `f` of the move (1 for the last piece)
    /// in `dt` seconds; a move whose rotary axes stand still is held back (see
    /// [`Writer::held`]).
    fn powered_pieces(
        &mut self,
        a: &[f64; 5],
        b: &[f64; 5],
        line: impl Fn(&Self, f64, f64) -> String,
        t: f64,
    ) {
        let pieces = super::power::pieces(self.model, a, b);
        let at = |f: f64| -> [f64; 5] { std::array::from_fn(|k| a[k] + f * (b[k] - a[k])) };
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
    fn write_coefficients(&mut self, a: &[f64; 5], b: &[f64; 5], coeffs: [f64; 6]) {
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
    fn power_changed(&mut self, v: f64) -> bool {
        let changed = self
            .last_power
            .is_none_or(|last| (v - last).abs() > POWER_STEP * last.abs().max(1e-9));
        if changed {
            self.last_power = Some(v);
        }
        changed
    }

    /// The header's lines on the power: the rule and how the dialect commands it.
    fn power_header(&mut self) {
        let Some(p) = self.opts.power else {
            self.comment(
                "power: not commanded (no technology): the beam is switched on and off only",
            );
            return;
        };
        self.comment(&format!(
            "power: {} % at {} mm/min of the tool tip, following the tip speed, floor {} %, pierce {} %",
            p.cut_percent, p.reference_feed_mm_per_min, p.min_percent, p.pierce_percent
        ));
        match self.opts.dialect {
            Dialect::Linuxcnc | Dialect::LinuxcncTcp => {
                self.comment("power: HAL power = clamp[E0 x tip speed in mm/s, E1, 100], E0 = % per mm/s, E1 = floor [M68 E1 = pierce power]");
                self.comment("power: HAL tip speed = |d[X,Y,Z]/dt + [E2,E3,E4] d[tilt]/dt + [E5,E6,E7] dC/dt|, rotary rates in deg/s");
                self.comment("power: E2..E7 mm/deg, set with M67 [synchronized with the next block] where the rotary axes move");
            }
            Dialect::Generic => self.comment("power: S = % per block from kerf's planned tip speed"),
            Dialect::Sinumerik => self.comment("power: FCTDEF[1, floor, 100, 0, % per mm/min] on $AC_VACTW by synchronized action ID=1"),
        }
    }

    /// The pierce power, before the beam comes on at the pierce point.
    fn pierce_power(&mut self) {
        let Some(p) = self.opts.power else {
            return;
        };
        let pierce = power_number(p.pierce_percent.min(100.0));
        match self.opts.dialect {
            Dialect::Linuxcnc | Dialect::LinuxcncTcp => {
                self.line("M68 E0 Q0");
                self.line(&format!("M68 E1 Q{pierce}"));
                if self.coeffs != [0.0; 6] {
                    for j in 2..8 {
                        self.line(&format!("M68 E{j} Q0"));
                    }
                    self.coeffs = [0.0; 6];
                }
            }
            Dialect::Generic => self.line(&format!("S{pierce}")),
            Dialect::Sinumerik => self.line(&format!("FCTDEF(1,{pierce},{pierce},{pierce},0)")),
        }
        self.last_power = None;
    }

    /// The cut's power rule, after the pierce dwell and before the descent: the floor (and on
    /// Sinumerik the slope); the speed-following values come with the blocks.
    fn cut_power(&mut self) {
        let Some(p) = self.opts.power else {
            return;
        };
        let floor = power_number(p.min_percent.min(p.cut_percent * self.factor));
        match self.opts.dialect {
            Dialect::Linuxcnc | Dialect::LinuxcncTcp => {
                let k = feed_number(p.per_mm_s(self.factor));
                self.line(&format!("M67 E1 Q{floor}"));
                self.line(&format!("M67 E0 Q{k}"));
            }
            Dialect::Generic => {}
            Dialect::Sinumerik => {
                let k = feed_number(p.per_mm_s(self.factor) / 60.0);
                self.line(&format!("FCTDEF(1,{floor},100,0,{k})"));
            }
        }
    }

    /// The power outputs back to zero at the program's end.
    pub(super) fn power_off(&mut self) {
        if self.opts.power.is_none() {
            return;
        }
        match self.opts.dialect {
            Dialect::Linuxcnc | Dialect::LinuxcncTcp => {
                for j in 0..8 {
                    self.line(&format!("M68 E{j} Q0"));
                }
            }
            Dialect::Generic => self.line("S0"),
            Dialect::Sinumerik => self.line("CANCEL(1)"),
        }
    }

    /// The cutting block `b`, taking `t` seconds.
    pub(super) fn cut(&mut self, b: &Block, t: f64) {
        match self.opts.dialect {
            Dialect::Generic | Dialect::Linuxcnc | Dialect::LinuxcncTcp => {
                // Arcs become chords within the chord tolerance (eq 18), the block's time
                // shared in proportion to the path parameter.
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
                    if self.opts.dialect == Dialect::LinuxcncTcp {
                        self.tcp_move(b.pose_at(s).0, q, t * share);
                    } else {
                        self.raw_move(q, t * share, if turn { 0.0 } else { s - s0 });
                    }
                    for &(_, on) in switches.iter().filter(|w| w.0 == s) {
                        self.joint_switch(on);
                    }
                    s0 = s;
                }
                if !turn {
                    self.path_s += b.length();
                }
            }
            Dialect::Sinumerik => {
                let p = b.end_tip();
                let u = b.end_tool_axis;
                let mut l = match &b.geometry {
                    Geometry::Arc(a) => format!(
                        "CIP X{} Y{} Z{} I1={} J1={} K1={} A3={} B3={} C3={}",
                        self.num(p.x),
                        self.num(p.y),
                        self.num(p.z),
                        self.num(a.mid.x),
                        self.num(a.mid.y),
                        self.num(a.mid.z),
                        self.num(u.x),
                        self.num(u.y),
                        self.num(u.z)
                    ),
                    _ => format!("G1 {}", self.tip_words(&p, &u)),
                };
                if !matches!(b.geometry, Geometry::Turn { .. }) {
                    let f = format!("{:.1}", b.length() / t * 60.0);
                    if self.last_f.as_deref() != Some(f.as_str()) {
                        l.push_str(" F");
                        l.push_str(&f);
                        self.last_f = Some(f);
                    }
                }
                self.line(&l);
            }
        }
    }
}

/// `M<m> P<n>` (LinuxCNC's digital outputs, `m` in 62..=65): `(m, n)`.
fn digital_output(line: &str) -> Option<(u32, u32)> {
    let mut words = line.split_whitespace();
    let m = words.next()?.strip_prefix('M')?.parse().ok()?;
    let p = words.next()?.strip_prefix('P')?.parse().ok()?;
    (words.next().is_none() && (62..=65).contains(&m)).then_some((m, p))
}

/// The lines that switch the beam off and on over a micro-joint: on LinuxCNC the synchronized
/// `M63`/`M62` on the outputs the machine's beam codes switch (`M62`-`M65 P<n>` only); in the
/// generic dialect the machine's beam codes themselves.
///
/// # Errors
/// [`InterpError::BadParameter`] for the Sinumerik dialect, the controller's kerf
/// compensation, or LinuxCNC beam codes that are not `M62`-`M65 P<n>`.
pub(super) fn joint_codes(
    opts: &GcodeOptions,
    process: &ProcessCodes,
) -> crate::error::Result<(Vec<String>, Vec<String>)> {
    let refuse = |reason: &'static str| {
        Err(crate::error::InterpError::BadParameter {
            name: "micro_joints",
            value: 1.0,
            reason,
        })
    };
    if opts.cutter_compensation.iter().any(Option::is_some) {
        return refuse("micro-joints are not written while the controller compensates the kerf (LinuxCNC sets no output then); compensate in the computer");
    }
    match opts.dialect {
        Dialect::Sinumerik => refuse("micro-joints are written for the linuxcnc and generic dialects (the Sinumerik dialect's arcs and merged lines are not split)"),
        Dialect::Generic => Ok((process.beam_off.clone(), process.beam_on.clone())),
        Dialect::Linuxcnc | Dialect::LinuxcncTcp => {
            let map = |lines: &[String], m: u32| -> Option<Vec<String>> {
                lines
                    .iter()
                    .map(|l| digital_output(l).map(|(_, p)| format!("M{m} P{p}")))
                    .collect()
            };
            match (map(&process.beam_off, 63), map(&process.beam_on, 62)) {
                (Some(off), Some(on)) if !off.is_empty() && !on.is_empty() => Ok((off, on)),
                _ => refuse("micro-joints on LinuxCNC need beam codes of the form M62-M65 P<n> (switched with motion as M63/M62 at the joints)"),
            }
        }
    }
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
fn feed_number(f: f64) -> String {
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
) -> (nalgebra::Point3<f64>, [f64; 5], nalgebra::Vector3<f64>, f64) {
    let (tilt, c) = (b.end_axes[3], b.end_axes[4]);
    let u = model.tool_axis(tilt, c);
    let h = process.pierce_standoff.max(crate::EXIT_RETRACT_MIN_MM);
    let p = b.end_tip() + u * h;
    let lin = model.linear_axes(&p, tilt, c);
    (p, [lin[0], lin[1], lin[2], tilt, c], u, h)
}

/// The pierce point of the cut starting with `b` (`pierce_standoff` above its start along the
/// tool axis), the machine axes there (the start's rotary axes) and the tool axis.
pub(super) fn pierce_point<M: AxisModel + ?Sized>(
    model: &M,
    process: &ProcessCodes,
    b: &Block,
) -> (nalgebra::Point3<f64>, [f64; 5], nalgebra::Vector3<f64>) {
    let (tilt, c) = (b.start_axes[3], b.start_axes[4]);
    let u = model.tool_axis(tilt, c);
    let h = process.pierce_standoff;
    let pierce = b.start_tip() + u * h;
    let q = if h > 0.0 {
        let lin = model.linear_axes(&pierce, tilt, c);
        [lin[0], lin[1], lin[2], tilt, c]
    } else {
        b.start_axes
    };
    (pierce, q, u)
}
