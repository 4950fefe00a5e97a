//! The command line, as clap definitions. Each subcommand's work lives in its own module.

use std::path::PathBuf;

use clap::{Args, Parser, Subcommand};

/// Turns NURBS cut contours into 5-axis laser cutting motion.
#[derive(Debug, Parser)]
#[command(
    name = "kerf",
    version,
    propagate_version = true,
    after_help = "Examples:\n  kerf validate fixtures/mixed.json\n  kerf discretize fixtures/mixed.json --tolerance 0.01 -o mixed.toolpath.json\n  kerf validate --json part.json > summary.json\n\nExit status: 0 success, 1 invalid or unreadable input, 2 usage error.\nFile formats: docs/formats.md (kerf.curves/1 in, kerf.toolpath/1 out)."
)]
pub(crate) struct Cli {
    /// What to do.
    #[command(subcommand)]
    pub(crate) command: Command,
}

/// The subcommands.
#[derive(Debug, Subcommand)]
pub(crate) enum Command {
    /// Check a kerf.curves/1 file and summarise its curves and surfaces.
    ///
    /// Reads the file (and any STL files it names), checks every value, and prints one line
    /// per curve (id, degree, control points, rational or not, parameter domain, length in mm,
    /// number of C0 corners, closed or not, carrying surface) and per surface (type and size).
    /// On the first defect it prints `error: <file>: <JSON path>: <defect>` to standard error
    /// and exits with status 1.
    #[command(
        after_help = "Examples:\n  kerf validate fixtures/circle.json\n  kerf validate --json fixtures/mixed.json\n  cat part.json | kerf validate -    (STL paths are then relative to the current directory)"
    )]
    Validate(ValidateArgs),

    /// Cutting points with a certified chord error for every curve, as kerf.toolpath/1.
    ///
    /// Places cutting points after the reference-sphere method (paper 004) so that every
    /// segment's chord error is proven <= the tolerance and every C0 corner is a cutting point.
    /// Prints a summary to standard error: curves, points, worst certified chord error, the
    /// theoretical minimum N* and the time.
    #[command(
        after_help = "Examples:\n  kerf discretize fixtures/mixed.json --tolerance 0.01 -o mixed.toolpath.json\n  kerf discretize fixtures/realdata/occt_propeller.json -t 0.01 --normals -o propeller.toolpath.json\n  kerf discretize part.json -t 0.001 --max-segment-length 20 -o -\n  kerf discretize part.json -t 0.01 --strategy equal-parameter --json"
    )]
    Discretize(DiscretizeArgs),

    /// Machine axes for a toolpath with normals, as kerf.axes/1.
    ///
    /// Solves the inverse kinematics of the machine for every pose, choosing the solution and
    /// the turn of a continuous C axis for continuity within the axis limits, keeps C at the
    /// pole, splits rotary steps above --max-rotary-step and inserts poses until the tool tip
    /// stays within --linearization-tolerance of the straight segments while the axes move
    /// linearly.
    #[command(
        after_help = "Examples:\n  kerf post part.toolpath.json --machine fixtures/machines/ac_head.json -o part.axes.json\n  kerf post part.toolpath.json -m fixtures/machines/table_table.json --max-rotary-step 2 --json"
    )]
    Post(PostArgs),

    /// The whole pipeline: discretize, normals, machine axes, interpolation and G-code, with a
    /// report and a picture, in one output directory.
    ///
    /// Writes toolpath.json, axes.json, program.nc, setpoints.csv, report.json, plot.svg and view.html into
    /// --out, all at once after every stage has succeeded (a failed run leaves the directory as
    /// it was). Curves without a surface are cut with a vertical beam.
    #[command(
        after_help = "Examples:\n  kerf run fixtures/dome.json --machine fixtures/machines/ac_head.json --tolerance 0.01 --out out\n  kerf run part.json -m machine.json -t 0.005 --feed 4000 --dialect sinumerik --out part-out"
    )]
    Run(Box<RunArgs>),

    /// Refresh the interactive 3D view (view.html) of a `kerf run` output directory.
    ///
    /// Reads the scene the directory's view.html holds and writes the page again with this
    /// version's viewer and the warnings of the directory's report.json (kerf run writes
    /// view.html itself: open it in a browser, no network needed).
    #[command(after_help = "Examples:\n  kerf view out")]
    View(ViewArgs),

    /// Interpolate a program: per-cycle machine axis set-points (paper 000's time-division
    /// lines and 3-point space arcs, with a look-ahead feed plan within every axis limit).
    ///
    /// Takes a kerf.axes/1 file, or a kerf.toolpath/1 file (then solved on the machine first).
    /// Fits 3-point space arcs where they stay within the fit tolerance, plans the feed so that
    /// no axis exceeds its velocity or acceleration limit in any cycle, and writes one CSV row
    /// per cycle (`t,X,Y,Z,<tilt>,C`).
    #[command(
        after_help = "Examples:\n  kerf interpolate part.axes.json --machine fixtures/machines/ac_head.json --feed 6000 --cycle 0.001 --csv part.csv\n  kerf interpolate part.toolpath.json -m fixtures/machines/fork_head.json --feed 3000 --json"
    )]
    Interpolate(InterpolateArgs),

    /// Write the G-code program of a path in one of eight dialects (--dialect): raw machine
    /// axes (generic, linuxcnc) or the controller's tool-tip control (sinumerik TRAORI with
    /// CIP arcs, linuxcnc-tcp, fanuc, fanuc-ijk, heidenhain, heidenhain-axes).
    #[command(
        after_help = "Examples:\n  kerf gcode part.axes.json -m fixtures/machines/ac_head.json --feed 6000 -o part.nc\n  kerf gcode part.toolpath.json -m fixtures/machines/ac_head.json --feed 6000 --dialect sinumerik -o part.mpf\n  kerf gcode part.axes.json -m fixtures/machines/ac_head.json --feed 6000 --dialect linuxcnc -o part.ngc"
    )]
    Gcode(GcodeArgs),

    /// Verify a kerf.toolpath/1 file against its curves, independently, by brute force.
    ///
    /// Works on toolpaths from any tool and trusts nothing in them: measures the chord error
    /// of every segment by dense sampling (every knot inside included) and golden-section
    /// refinement, and checks the ids and their order, params (strictly increasing, from one
    /// end of the domain to the other), every point on the curve at its param, every C0 corner
    /// a cutting point, unit normals, each segment's error against the tolerance and the
    /// file's max_chord_error against the measurement. Prints a table per path and every
    /// violation (path, segment, params, measured error vs tolerance); exits with status 1 if
    /// there is any.
    #[command(
        after_help = "Examples:\n  kerf check fixtures/mixed.json mixed.toolpath.json\n  kerf check part.json other-cam.toolpath.json --json > report.json\n  kerf discretize part.json -o - | kerf check part.json -"
    )]
    Check(crate::check::CheckArgs),

    /// Draw a toolpath on its curves (and the machine axes) as one SVG picture.
    ///
    /// Top, front, side and isometric views of the curves, cutting points and tool axes, with
    /// segments coloured by chord error / tolerance; a chart of every segment's chord error
    /// against the tolerance; with --axes, the machine axes over the point index with the
    /// machine's limits dashed. Opens in any browser.
    #[command(
        after_help = "Examples:\n  kerf plot fixtures/mixed.json mixed.toolpath.json -o mixed.svg\n  kerf plot part.json part.toolpath.json --axes part.axes.json --machine fixtures/machines/ac_head.json -o part.svg"
    )]
    Plot(crate::plot::PlotArgs),

    /// Read a STEP or IGES file's cut contours and the faces they lie on into kerf.curves/1.
    ///
    /// Takes the curves of the geometric sets (composite curves joined into one NURBS curve
    /// each, C0 at every join, gaps up to --close-gaps closed, larger gaps opened), or with
    /// --edges the boundary loops of faces; finds the faces each contour lies on by projection
    /// and writes them as exact NURBS surfaces, `Su x Sv` outward. Lengths are converted to mm.
    /// Says what it took and what it skipped; a file with no usable contour is an error.
    #[command(
        after_help = "Examples:\n  kerf import fixtures/step/composite_mm.step -o part.curves.json\n  kerf import bracket.stp --edges --faces 120 -o bracket.curves.json\n  kerf run part.step --machine fixtures/machines/ac_head.json --out part-out"
    )]
    Import(crate::import::ImportArgs),
}

/// Arguments of `kerf validate`.
#[derive(Debug, Args)]
pub(crate) struct ValidateArgs {
    /// The kerf.curves/1 file to check; `-` reads standard input.
    #[arg(value_name = "CURVES.json")]
    pub(crate) curves: PathBuf,

    /// Print the summary as JSON on standard output (also on failure, as
    /// {"valid": false, "error": ...}).
    #[arg(long)]
    pub(crate) json: bool,
}

/// Arguments of `kerf discretize`.
#[derive(Debug, Args)]
pub(crate) struct DiscretizeArgs {
    /// The kerf.curves/1 file; `-` reads standard input.
    #[arg(value_name = "CURVES.json")]
    pub(crate) curves: PathBuf,

    /// Chord tolerance in mm (> 0, at most 10): every segment's chord error is at most this.
    #[arg(short, long, default_value_t = 0.01, value_name = "MM", value_parser = crate::guard::tolerance_mm)]
    pub(crate) tolerance: f64,

    /// Output kerf.toolpath/1 file (`-` for standard output). Default: `<input stem>.toolpath.json`
    /// in the current directory.
    #[arg(short, long, value_name = "TOOLPATH.json")]
    pub(crate) output: Option<PathBuf>,

    /// Lower edge of the accepted chord-error band, as a fraction of the tolerance (0 < band <
    /// 1; default 0.97). Higher: fewer points, slower.
    #[arg(long, value_name = "FRACTION", value_parser = crate::guard::fraction)]
    pub(crate) band: Option<f64>,

    /// Longest chord allowed, in mm (machines limit block length).
    #[arg(long, value_name = "MM", value_parser = crate::guard::segment_length_mm)]
    pub(crate) max_segment_length: Option<f64>,

    /// Shortest sphere radius the search proposes, in mm (the tolerance still wins).
    #[arg(long, value_name = "MM", value_parser = crate::guard::segment_length_mm)]
    pub(crate) min_segment_length: Option<f64>,

    /// Most cutting points per curve (default 50,000,000); a curve that needs more is refused
    /// before any work.
    #[arg(long, value_name = "N", value_parser = clap::value_parser!(u64).range(2..=1_000_000_000))]
    pub(crate) max_points: Option<u64>,

    /// Largest turn of the tangent over one segment (between the tangents at any two of its
    /// points, certified from the hodograph), in degrees.
    #[arg(long, value_name = "DEG", value_parser = crate::guard::angle_deg)]
    pub(crate) max_turn: Option<f64>,

    /// How cutting points are placed (the classic methods carry the same guarantee).
    #[arg(long, value_enum, default_value_t = StrategyArg::ReferenceSphere)]
    pub(crate) strategy: StrategyArg,

    /// Give every cutting point the unit normal of its curve's surface: points become
    /// `[x, y, z, i, j, k]`. Every curve must name a surface.
    #[arg(long)]
    pub(crate) normals: bool,

    /// With --normals: a cutting point farther than this from its surface is an error (mm,
    /// default 0.01), unless its curve states a looser on_surface_tolerance_mm of its own (then
    /// that one, with a warning naming the curve).
    #[arg(long, value_name = "MM", requires = "normals", value_parser = crate::guard::tolerance_mm)]
    pub(crate) on_surface_tolerance: Option<f64>,

    /// With --normals: the largest angle between neighbouring normals; points are inserted
    /// until it holds (degrees, default 1).
    #[arg(long, value_name = "DEG", requires = "normals", value_parser = crate::guard::normal_step_deg)]
    pub(crate) max_normal_step: Option<f64>,

    /// With --normals, for meshes: faces meeting at more than this angle form a sharp edge
    /// whose normals are not blended (degrees, default 30).
    #[arg(long, value_name = "DEG", requires = "normals", value_parser = crate::guard::angle_deg)]
    pub(crate) crease_angle: Option<f64>,

    /// Print the summary as one JSON object instead of a sentence.
    #[arg(long)]
    pub(crate) json: bool,

    /// Print no summary.
    #[arg(short, long)]
    pub(crate) quiet: bool,
}

/// `--strategy` values.
#[derive(Debug, Clone, Copy, PartialEq, Eq, clap::ValueEnum)]
pub(crate) enum StrategyArg {
    /// After the reference-sphere method of paper 004: the step from the arc's Taylor model,
    /// certified (default).
    ReferenceSphere,
    /// Longest certified step by bisection on the parameter.
    EqualError,
    /// Equal chord lengths, smallest certifying count.
    EqualChord,
    /// Equal parameter steps, smallest certifying count.
    EqualParameter,
}

impl From<StrategyArg> for kerf_discretize::Strategy {
    fn from(s: StrategyArg) -> Self {
        match s {
            StrategyArg::ReferenceSphere => Self::ReferenceSphere,
            StrategyArg::EqualError => Self::EqualError,
            StrategyArg::EqualChord => Self::EqualChordLength,
            StrategyArg::EqualParameter => Self::EqualParameter,
        }
    }
}

/// Arguments of `kerf post`.
#[derive(Debug, Args)]
pub(crate) struct PostArgs {
    /// The kerf.toolpath/1 file, with normals (`[x, y, z, i, j, k]` points).
    #[arg(value_name = "TOOLPATH.json")]
    pub(crate) toolpath: PathBuf,

    /// The kerf.machine/1 file.
    #[arg(short, long, value_name = "MACHINE.json")]
    pub(crate) machine: PathBuf,

    /// Output kerf.axes/1 file (`-` for standard output). Default: `<input stem>.axes.json` in
    /// the current directory.
    #[arg(short, long, value_name = "AXES.json")]
    pub(crate) output: Option<PathBuf>,

    /// Largest tool-tip deviation from the straight segment while the axes move linearly, in
    /// mm (default 0.005).
    #[arg(long, value_name = "MM", value_parser = crate::guard::tolerance_mm)]
    pub(crate) linearization_tolerance: Option<f64>,

    /// Largest rotary-axis move between two points, in degrees (default: no limit).
    #[arg(long, value_name = "DEG", value_parser = crate::guard::angle_deg)]
    pub(crate) max_rotary_step: Option<f64>,

    /// How far the tool axis may tilt from the surface normal to save rotary motion, degrees
    /// (default 0, the exact normal; 1 suits sheet metal): C is held near the pole, creases are
    /// turned over a distance, small wiggles of the normal are not followed.
    #[arg(long, value_name = "DEG", value_parser = crate::guard::tilt_deg)]
    pub(crate) tilt_tolerance: Option<f64>,

    /// Where the part goes on the machine: `auto` (every pose within the axis limits, the
    /// motion centred in the travel, contours turned to the side the head can reach, the part
    /// turned by quarter turns if it does not fit as modelled) or `X,Y,Z[,RX,RY,RZ]` (mm,
    /// degrees; `p' = Rz Ry Rx p + t`). Default: where the CAD model put it.
    #[arg(long, value_name = "auto|X,Y,Z[,RX,RY,RZ]", value_parser = kerf_pipeline::PlaceMode::parse, allow_hyphen_values = true)]
    pub(crate) place: Option<kerf_pipeline::PlaceMode>,

    /// Tool axes within this angle of the C axis count as the pole, in degrees (default
    /// 5.73e-5, which is 1e-6 rad).
    #[arg(long, value_name = "DEG", value_parser = crate::guard::small_angle_deg)]
    pub(crate) pole_tolerance: Option<f64>,

    /// Print the summary as one JSON object.
    #[arg(long)]
    pub(crate) json: bool,

    /// Print no summary.
    #[arg(short, long)]
    pub(crate) quiet: bool,
}

/// The inputs shared by `kerf interpolate` and `kerf gcode`.
#[derive(Debug, Args)]
pub(crate) struct MotionArgs {
    /// A kerf.axes/1 file (from `kerf post`) or a kerf.toolpath/1 file.
    #[arg(value_name = "AXES_OR_TOOLPATH.json")]
    pub(crate) input: PathBuf,

    /// The kerf.machine/1 file.
    #[arg(short, long, value_name = "MACHINE.json")]
    pub(crate) machine: PathBuf,

    /// Programmed cutting feed, mm/min.
    #[arg(short, long, value_name = "MM_PER_MIN", value_parser = crate::guard::feed_mm_per_min)]
    pub(crate) feed: f64,

    /// Interpolation cycle, seconds (from 1e-5 to 0.1: 10 microseconds to 100 milliseconds).
    #[arg(short, long, default_value_t = 0.001, value_name = "S", value_parser = crate::guard::cycle_s)]
    pub(crate) cycle: f64,

    /// Arc-fit tolerance, mm (default: the toolpath's tolerance, else 0.001).
    #[arg(long, value_name = "MM", value_parser = crate::guard::tolerance_mm)]
    pub(crate) fit_tolerance: Option<f64>,

    /// Chord error allowed between two set-points on an arc, mm (caps the feed on small
    /// radii; default 0.001).
    #[arg(long, value_name = "MM", value_parser = crate::guard::tolerance_mm)]
    pub(crate) chord_tolerance: Option<f64>,

    /// Between two contours the head backs off this far along the tool axis, traverses, and
    /// approaches the next start along its tool axis (mm, 0 to 1000; 0 = one straight rapid at
    /// cutting height). Choose it so that the traverse clears the part.
    #[arg(long, default_value_t = 10.0, value_name = "MM", value_parser = crate::guard::retract_mm)]
    pub(crate) retract: f64,

    /// The traverses between cuts: > 0 runs each through the waypoints the axes file records
    /// for it (its `traverse` key, checked by `kerf run` to keep this clearance from the part),
    /// as `kerf run`'s own program does; 0 = the unchecked retract and straight traverse
    /// everywhere. The axes file's traverses were planned for the clearance `kerf run` was
    /// given: without the part's surfaces they cannot be planned again here (mm, 0 to 1000).
    #[arg(long, default_value_t = 5.0, value_name = "MM", value_parser = crate::guard::clearance_mm)]
    pub(crate) clearance: f64,

    /// The kerf.curves/1 file a toolpath input was made from: every segment is certified
    /// against its curve again, so the program's budget states a proven chord term. Without it
    /// a toolpath's `tolerance` is stated as the file's claim; an axes file records none.
    #[arg(long, value_name = "CURVES.json")]
    pub(crate) curves: Option<PathBuf>,
}

/// Arguments of `kerf interpolate`.
#[derive(Debug, Args)]
pub(crate) struct InterpolateArgs {
    /// Inputs.
    #[command(flatten)]
    pub(crate) motion: MotionArgs,

    /// Write the set-points CSV here (one row per cycle; `-` for standard output).
    #[arg(long, value_name = "OUT.csv")]
    pub(crate) csv: Option<PathBuf>,

    /// Print the summary as one JSON object.
    #[arg(long)]
    pub(crate) json: bool,

    /// Print no summary.
    #[arg(short, long)]
    pub(crate) quiet: bool,
}

/// Arguments of `kerf gcode`.
#[derive(Debug, Args)]
pub(crate) struct GcodeArgs {
    /// Inputs.
    #[command(flatten)]
    pub(crate) motion: MotionArgs,

    /// The program file to write (`-` for standard output).
    #[arg(short, long, value_name = "OUT.nc")]
    pub(crate) output: PathBuf,

    /// The G-code dialect.
    #[arg(long, value_enum, default_value_t = DialectArg::Generic)]
    pub(crate) dialect: DialectArg,

    /// The controller's blending tolerance, mm (> 0, at most 10): a term of the tolerance budget
    /// (LinuxCNC `G64 P`, Sinumerik `CTOL`/`OTOL`).
    #[arg(long, default_value_t = kerf_interp::DEFAULT_BLEND_TOLERANCE, value_name = "MM", value_parser = crate::guard::blend_tolerance_mm)]
    pub(crate) blend_tolerance: f64,

    /// Print the summary as one JSON object.
    #[arg(long)]
    pub(crate) json: bool,

    /// Print no summary.
    #[arg(short, long)]
    pub(crate) quiet: bool,
}

/// Arguments of `kerf view`.
#[derive(Debug, Args)]
pub(crate) struct ViewArgs {
    /// The output directory of `kerf run`.
    #[arg(value_name = "DIR")]
    pub(crate) dir: PathBuf,
}

/// `--dialect` values.
#[derive(Debug, Clone, Copy, PartialEq, Eq, clap::ValueEnum)]
pub(crate) enum DialectArg {
    /// `G1 X Y Z A C F` with machine axis values.
    Generic,
    /// Sinumerik-style TRAORI: tool tip, orientation vector, CIP arcs.
    Sinumerik,
    /// LinuxCNC (trivkins): machine axes, G93 inverse-time feed, G64 P blending on cuts.
    Linuxcnc,
    /// LinuxCNC with its own tool-tip kinematics (xyzac-trt-kins for a table-table with
    /// conventional false, 5axiskins for a B fork head with tilt_sign -1): tip X Y Z in the
    /// workpiece frame and the rotary axes, G94 tip feed.
    LinuxcncTcp,
    /// Fanuc tool center point control G43.4: tip X Y Z in G54 with the rotary axes, G05.1 Q1
    /// look-ahead, G94 tip feed.
    Fanuc,
    /// Fanuc G43.5: tip X Y Z with the tool direction I J K (head machines only).
    FanucIjk,
    /// HEIDENHAIN Klartext under FUNCTION TCPM: numbered LN X Y Z TX TY TZ blocks (tip and
    /// tool direction), CYCL DEF 32 tolerance; no power that follows the speed.
    Heidenhain,
    /// HEIDENHAIN Klartext under FUNCTION TCPM with L X Y Z and the rotary axes.
    HeidenhainAxes,
}

impl From<DialectArg> for kerf_interp::Dialect {
    fn from(d: DialectArg) -> Self {
        match d {
            DialectArg::Generic => Self::Generic,
            DialectArg::Sinumerik => Self::Sinumerik,
            DialectArg::Linuxcnc => Self::Linuxcnc,
            DialectArg::LinuxcncTcp => Self::LinuxcncTcp,
            DialectArg::Fanuc => Self::Fanuc,
            DialectArg::FanucIjk => Self::FanucIjk,
            DialectArg::Heidenhain => Self::Heidenhain,
            DialectArg::HeidenhainAxes => Self::HeidenhainAxes,
        }
    }
}

/// Arguments of `kerf run`.
#[derive(Debug, Args)]
pub(crate) struct RunArgs {
    /// The kerf.curves/1 file, or a STEP file (.step, .stp: imported as `kerf import` does).
    #[arg(value_name = "CURVES.json")]
    pub(crate) curves: PathBuf,

    /// How contours and faces are taken from a STEP input.
    #[command(flatten)]
    pub(crate) step_args: crate::import::StepArgs,

    /// The kerf.machine/1 file.
    #[arg(short, long, value_name = "MACHINE.json")]
    pub(crate) machine: PathBuf,

    /// Chord tolerance in mm (> 0, at most 10; every segment's chord error is at most this).
    #[arg(short, long, default_value_t = 0.01, value_name = "MM", value_parser = crate::guard::tolerance_mm)]
    pub(crate) tolerance: f64,

    /// Output directory (created if needed).
    #[arg(short, long, default_value = "kerf-out", value_name = "DIR")]
    pub(crate) out: PathBuf,

    /// Programmed cutting feed, mm/min: this, else the technology entry's (--technology),
    /// else 6000.
    #[arg(short, long, value_name = "MM_PER_MIN", value_parser = crate::guard::feed_mm_per_min)]
    pub(crate) feed: Option<f64>,

    /// A technology table (`kerf.technology/1`): the entry of --material (and --thickness)
    /// sets the feed (unless --feed), the pierce time, height and power, the standoff and the
    /// kerf width (unless --kerf-width); its power follows the tip's speed, its small-hole rule
    /// slows small holes; the program header and the report name it.
    #[arg(long, value_name = "FILE", requires = "material")]
    pub(crate) technology: Option<PathBuf>,

    /// The material of the technology entry (compared without case), from --technology or
    /// else the machine file's `process.technology` table; an unknown one is refused with the
    /// known ones listed.
    #[arg(long, value_name = "NAME")]
    pub(crate) material: Option<String>,

    /// The sheet thickness of the technology entry, mm (needed where the material has several
    /// entries).
    #[arg(long, value_name = "MM", requires = "material", value_parser = crate::guard::positive_mm)]
    pub(crate) thickness: Option<f64>,

    /// Interpolation cycle, seconds (from 1e-5 to 0.1: 10 microseconds to 100 milliseconds).
    #[arg(short, long, default_value_t = 0.001, value_name = "S", value_parser = crate::guard::cycle_s)]
    pub(crate) cycle: f64,

    /// The G-code dialect.
    #[arg(long, value_enum, default_value_t = DialectArg::Generic)]
    pub(crate) dialect: DialectArg,

    /// The controller's blending tolerance, mm (> 0, at most 10): a term of the tolerance budget
    /// (LinuxCNC `G64 P`, Sinumerik `CTOL`/`OTOL`).
    #[arg(long, default_value_t = kerf_interp::DEFAULT_BLEND_TOLERANCE, value_name = "MM", value_parser = crate::guard::blend_tolerance_mm)]
    pub(crate) blend_tolerance: f64,

    /// Longest chord allowed, in mm.
    #[arg(long, value_name = "MM", value_parser = crate::guard::segment_length_mm)]
    pub(crate) max_segment_length: Option<f64>,

    /// Largest angle between neighbouring normals, degrees (default 1).
    #[arg(long, value_name = "DEG", value_parser = crate::guard::normal_step_deg)]
    pub(crate) max_normal_step: Option<f64>,

    /// Largest tool-tip deviation while the axes move linearly, mm (default 0.005).
    #[arg(long, value_name = "MM", value_parser = crate::guard::tolerance_mm)]
    pub(crate) linearization_tolerance: Option<f64>,

    /// Largest rotary-axis move between two points, degrees (default: no limit).
    #[arg(long, value_name = "DEG", value_parser = crate::guard::angle_deg)]
    pub(crate) max_rotary_step: Option<f64>,

    /// How far the tool axis may tilt from the surface normal to save rotary motion, degrees
    /// (default 0, the exact normal; 1 suits sheet metal): C is held near the pole, creases are
    /// turned over a distance, small wiggles of the normal are not followed.
    #[arg(long, value_name = "DEG", value_parser = crate::guard::tilt_deg)]
    pub(crate) tilt_tolerance: Option<f64>,

    /// Most cutting points of all curves together (default 1,000,000): a job that needs more
    /// is refused before the points are made (every stage, the program and the plot grow with
    /// them).
    #[arg(long, value_name = "N", value_parser = clap::value_parser!(u64).range(2..=1_000_000_000))]
    pub(crate) max_total_points: Option<u64>,

    /// Where the part goes on the machine: `auto` (every pose within the axis limits, the
    /// motion centred in the travel, contours turned to the side the head can reach, the part
    /// turned by quarter turns if it does not fit as modelled) or `X,Y,Z[,RX,RY,RZ]` (mm,
    /// degrees; `p' = Rz Ry Rx p + t`). Default: where the CAD model put it.
    #[arg(long, value_name = "auto|X,Y,Z[,RX,RY,RZ]", value_parser = kerf_pipeline::PlaceMode::parse, allow_hyphen_values = true)]
    pub(crate) place: Option<kerf_pipeline::PlaceMode>,

    /// Between two contours the head backs off this far along the tool axis, traverses, and
    /// approaches the next start along its tool axis (mm, 0 to 1000; 0 = one straight rapid at
    /// cutting height). Choose it so that the traverse clears the part.
    #[arg(long, default_value_t = 10.0, value_name = "MM", value_parser = crate::guard::retract_mm)]
    pub(crate) retract: f64,

    /// No traverse between cuts comes closer than this to the part's surfaces (the tool tip
    /// and a 20 mm nozzle along the tool axis, checked against the NURBS and mesh surfaces
    /// as the machine runs its rapids); the travel is lifted over the part where the straight
    /// one is not clear (mm, 0 to 1000; 0 = the unchecked retract and straight traverse).
    #[arg(long, default_value_t = 5.0, value_name = "MM", value_parser = crate::guard::clearance_mm)]
    pub(crate) clearance: f64,

    /// A contour whose only named surface is a wall at most this wide across it (a hole's or a
    /// slot's wall, the sheet's edge face, named instead of the sheet's face) is cut with the
    /// beam along the wall, through the sheet, and the lead-in on the side the wall's normal
    /// points to; the report lists them (`placement.walls`). mm, 0 to 100; 0 = the wall's
    /// normal is the tool axis, as for any surface.
    #[arg(long, default_value_t = 4.0, value_name = "MM", value_parser = crate::guard::wall_mm)]
    pub(crate) max_wall: f64,

    /// The kerf width: every path moves half of it toward its scrap side (inside a hole,
    /// outside an outline, the curve's `scrap` key), so that the cut edge lands on the
    /// contour; outside corners get an arc, inside corners are cut back, and a hole or slot
    /// smaller than the kerf is refused by name. mm, above 0 and at most 20. Without it the
    /// machine file's `process.kerf_width_mm` is used; with neither, the path is the contour.
    #[arg(long, value_name = "MM", value_parser = crate::guard::kerf_width_mm)]
    pub(crate) kerf_width: Option<f64>,

    /// With a kerf width (this run's or the machine file's), leave the kerf compensation to
    /// the controller: the program holds the contours themselves with the controller's
    /// compensation from each lead-in on. `--dialect linuxcnc`: G41.1/G42.1 D<kerf>, G40
    /// before the beam goes off; every compensated cut must stand the beam vertical with the
    /// rotary axes still, else the run is refused with the reason. `--dialect sinumerik`:
    /// CUT3DC with G41/G42 and OFFN=<kerf/2> (the active tool's radius must be 0), G40 after
    /// the beam is off; any tool orientation. Other dialects: refused.
    #[arg(long)]
    pub(crate) kerf_in_control: bool,

    /// The distance the head keeps from the part along every cut (contour, lead-in,
    /// lead-out), mm, or `off` [default: 1]: the machine file's `head` (else a 3 mm nozzle
    /// cone 25 mm long on a 90 mm body) standing at its `process.standoff_mm` must keep it from
    /// the part's surfaces, proven over the poses and the motion between them; a cut that
    /// comes closer is tilted within --tilt-tolerance to clear, else refused naming the
    /// stretch and the surface. The checked traverses (a --clearance above 0) keep it too: a
    /// route the head does not clear is not taken, and a traverse on which the head clears no
    /// route is refused by name. The report's `head` gives the figures per path, `traverses`
    /// those of the traverses. `off`: the head is not checked (the traverses keep --clearance
    /// with the tip and the nozzle line only).
    #[arg(long, value_name = "MM|off", value_parser = crate::guard::cut_clearance)]
    pub(crate) cut_clearance: Option<crate::guard::CutClearance>,

    /// Report cuts and traverses where the head comes closer than --cut-clearance as warnings
    /// instead of refusing the run.
    #[arg(long)]
    pub(crate) accept_head_collisions: bool,

    /// Micro-joints: leave LENGTH mm of each part's outline (and of each cut-out at least
    /// SPACING mm round) uncut every SPACING mm of path, away from corners and the lead-in; the
    /// beam is switched there with codes synchronized with motion (linuxcnc: M63/M62 on the
    /// output the machine's beam codes name; generic: the machine's codes). LENGTH in (0, 10],
    /// SPACING in [1, 1e5], LENGTH < SPACING.
    #[arg(long, value_name = "LENGTH,SPACING", value_parser = crate::guard::micro_joints)]
    pub(crate) micro_joints: Option<(f64, f64)>,

    /// Lead-in of every cut: the straight part from the pierce point, then the radius of the
    /// quarter arc that joins the contour tangentially on the scrap side, mm, each 0 to 1000
    /// (`0,0` pierces on the contour). Shrunk where the scrap is smaller (small holes).
    #[arg(long, value_name = "LINE,RADIUS", default_value = "2,1", value_parser = crate::guard::lead_in)]
    pub(crate) lead_in: (f64, f64),

    /// Lead-out: how far the cut runs on past its start on a closed contour, then the exit
    /// into the scrap, mm, each 0 to 1000.
    #[arg(long, value_name = "OVERCUT,EXIT", default_value = "0.5,1", value_parser = crate::guard::lead_out)]
    pub(crate) lead_out: (f64, f64),

    /// Print the report as JSON on standard output.
    #[arg(long)]
    pub(crate) json: bool,

    /// Print no summary.
    #[arg(short, long)]
    pub(crate) quiet: bool,
}

impl RunArgs {
    /// The lead-in and lead-out options these arguments ask for.
    pub(crate) fn lead_options(&self) -> kerf_process::LeadOptions {
        kerf_process::LeadOptions::default()
            .with_lead_in(self.lead_in.0, self.lead_in.1)
            .with_lead_out(self.lead_out.0, self.lead_out.1)
    }

    /// The traverse options these arguments ask for (`None`: unchecked traverses); the job
    /// raises their retract to `--retract` (`JobOptions::checked_traverse`).
    pub(crate) fn traverse_options(&self) -> Option<kerf_process::TraverseOptions> {
        (self.clearance > 0.0)
            .then(|| kerf_process::TraverseOptions::default().with_clearance(self.clearance))
    }
}
