//! The G-code dialects: the one `match` that registers each dialect's rules, and the process
//! codes resolved over a dialect's defaults.

use super::codes::{escape, ProcessCodes};
use super::dialects;
use super::writer::Rules;
use crate::error::{InterpError, Result};

/// G-code dialect.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[non_exhaustive]
pub enum Dialect {
    /// `G1 X Y Z A C F` with machine axis values, `G94` feed of the machine axes
    /// (RS274/NGC rule), `;` comments, `M30`.
    Generic,
    /// Sinumerik-style `TRAORI`: tool tip, orientation vector, `CIP` arcs, `G54`, `SOFT`,
    /// `G642` with `CTOL`/`OTOL`, `;` comments, `M30`.
    Sinumerik,
    /// LinuxCNC (trivkins, the machine's axis letters): inverse-time feed `G93`, `G64 P` on
    /// cuts and `G61` on rapids, `( ... )` comments, `M2`.
    Linuxcnc,
    /// LinuxCNC with its own tool-tip kinematics (`xyzac-trt-kins` for a `table-table`
    /// machine, `5axiskins` for a B fork head, see
    /// [`linuxcnc_kinematics`](crate::linuxcnc_kinematics)): `X Y Z` the tool
    /// tip in the workpiece frame and the rotary axes, `G94` with `F` the tip's feed in
    /// mm/min, `G64 P` on cuts and `G61` on rapids, `( ... )` comments, `M2`.
    LinuxcncTcp,
    /// Fanuc tool center point control `G43.4` (type 1): `X Y Z` the tool tip in the workpiece
    /// frame `G54` with the rotary axes, `G05.1 Q1` look-ahead, `G94` tip feed, `G49` at the
    /// end, `( ... )` comments, `%`, `O1000`, `M30`.
    Fanuc,
    /// Fanuc `G43.5` (type 2): the tool tip with the tool direction `I J K`, for head machines
    /// only (a table machine raises alarm PS5421: refused by name); otherwise as
    /// [`Dialect::Fanuc`].
    FanucIjk,
    /// HEIDENHAIN Klartext under `FUNCTION TCPM F TCP AXIS POS PATHCTRL AXIS`: numbered
    /// blocks `LN X Y Z TX TY TZ F`, the tool tip with the unit tool direction (the TNC chooses
    /// the rotary solution), `CYCL DEF 32` tolerance from the budget, `FMAX` rapids, `;`
    /// comments, `BEGIN PGM`/`END PGM`. No power that follows the speed (the header says so).
    Heidenhain,
    /// As [`Dialect::Heidenhain`] with `L X Y Z <tilt> C F`: the tool tip with the rotary axes
    /// kerf solved.
    HeidenhainAxes,
}

impl Dialect {
    /// The dialect's rules: the one place a dialect is registered (its file under
    /// `output/dialects/`).
    pub(super) fn rules(self) -> &'static dyn Rules {
        match self {
            Dialect::Generic => &dialects::Generic,
            Dialect::Sinumerik => &dialects::Sinumerik,
            Dialect::Linuxcnc => &dialects::Linuxcnc,
            Dialect::LinuxcncTcp => &dialects::LinuxcncTcp,
            Dialect::Fanuc => &dialects::Fanuc { ijk: false },
            Dialect::FanucIjk => &dialects::Fanuc { ijk: true },
            Dialect::Heidenhain => &dialects::Heidenhain { axes: false },
            Dialect::HeidenhainAxes => &dialects::Heidenhain { axes: true },
        }
    }

    /// Whether the dialect can program `model`'s machine: a tool-tip dialect for a controller
    /// that runs its own kinematics needs one it knows (`linuxcnc-tcp`, see
    /// [`linuxcnc_kinematics`](crate::linuxcnc_kinematics)), `fanuc-ijk` a head machine. The
    /// G-code writer checks it too; a pipeline checks it first, before any work.
    ///
    /// # Errors
    /// [`InterpError::DialectMachine`] naming the mismatch.
    pub fn check_machine<M: crate::AxisModel>(self, model: &M) -> Result<()> {
        self.rules().machine_lines(model).map(|_| ())
    }

    /// True where the dialect commands a [`LaserPower`](crate::LaserPower) that follows the
    /// speed; false where the program switches the beam only and its header says why
    /// (`heidenhain`: no power word acts with the motion in Klartext).
    pub fn commands_power(self) -> bool {
        self.rules().power_refusal().is_none()
    }

    /// True where the dialect writes the controller's own kerf compensation (`linuxcnc`:
    /// `G41.1`/`G42.1`; `sinumerik`: `CUT3DC` with `G41`/`G42`): the program then holds the
    /// contours themselves ([`GcodeOptions::cutter_compensation`](crate::GcodeOptions)).
    pub fn controller_compensation(self) -> bool {
        self.rules().controller_compensation()
    }

    /// True where that compensation offsets in X and Y only (`linuxcnc`'s `G41.1`), so that
    /// every compensated cut must stand the beam vertical with the rotary axes still.
    pub fn compensation_xy_only(self) -> bool {
        self.rules().compensation_xy_only()
    }

    /// How the controller compensates a kerf of `kerf_width_mm`, in the program header's
    /// words (`G41.1/G42.1 D0.2`, `CUT3DC G41/G42 OFFN=0.1 (...)`); empty where it cannot.
    pub fn compensation_words(self, kerf_width_mm: f64) -> String {
        self.rules().compensation_words(kerf_width_mm)
    }

    /// The dialect's name as the CLI spells it.
    pub fn name(self) -> &'static str {
        self.rules().name()
    }

    /// True for the dialects whose blocks join neighbouring poses only: no arcs, no lines
    /// merged over several poses. The raw-axis dialects (the controller interpolates the axes
    /// linearly, so only the poses' checked non-linearity holds) and `linuxcnc-tcp` (LinuxCNC
    /// interpolates its rotary axes linearly in each block, so a merged line would carry the
    /// tool axis off the poses between its ends; it writes no 3D arcs).
    pub fn raw_axes(self) -> bool {
        self.rules().joins_poses_only()
    }

    /// The process codes used when the machine file's `process` object lacks a key:
    ///
    /// | dialect | beam on | beam off | dwell | standoff |
    /// |---|---|---|---|---|
    /// | linuxcnc, linuxcnc-tcp | `M64 P0` | `M65 P0` | 0.2 s | 1.5 mm |
    /// | generic | `M3` | `M5` | 0.2 s | 1.5 mm |
    /// | sinumerik, fanuc, fanuc-ijk, heidenhain, heidenhain-axes | `M3` | `M5` | 0.2 s | 1.5 mm |
    ///
    /// LinuxCNC's `M64`/`M65` switch the output when every motion queued before them has
    /// finished (they break blending): the dwell after `M64` runs with the beam on and the
    /// beam goes off where the cut ends. (`M62`/`M63` act at the start of the *next* motion:
    /// a machine that names `M62 P<n>` gets its pierce lit with the immediate `M64 P<n>`, so
    /// that the dwell runs with the beam on, and every program ends with a retract after its
    /// last beam-off, so that a last `M63` fires too. Micro-joints always switch with the
    /// synchronized `M63`/`M62`.)
    pub fn default_process(self) -> ProcessCodes {
        super::writer::default_process(self.rules())
    }

    /// One whole-line comment in the dialect's syntax, its text escaped as by
    /// [`comment_text`](super::comment_text) but not cut (text from the input must already
    /// have been through it, which cuts it).
    pub(super) fn comment(self, text: &str) -> String {
        self.rules().comment(&escape(text, usize::MAX))
    }
}

impl ProcessCodes {
    /// `process` over the defaults of `dialect`, checked as the machine reader checks a file
    /// (a library caller may have built `process` by hand).
    ///
    /// # Errors
    /// [`InterpError::Process`] naming the key, as
    /// `process.pierce_dwell_s: must be finite and >= 0 (got -1)`.
    pub fn resolve(dialect: Dialect, process: &kerf_kinematics::Process) -> Result<Self> {
        process
            .validate()
            .map_err(|e| InterpError::Process(e.into()))?;
        let d = dialect.default_process();
        Ok(Self {
            beam_on: process.beam_on.clone().unwrap_or(d.beam_on),
            beam_off: process.beam_off.clone().unwrap_or(d.beam_off),
            pierce_dwell_s: process.pierce_dwell_s.unwrap_or(d.pierce_dwell_s),
            pierce_standoff: process.pierce_standoff.unwrap_or(d.pierce_standoff),
        })
    }
}
