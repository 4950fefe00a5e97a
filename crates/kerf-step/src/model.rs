//! Typed access to the entity table: references followed with errors naming the entity,
//! points and directions in millimetres, placements, and the file's units.

use nalgebra::{Point3, Vector3};

use crate::error::{Result, StepError};
use crate::parser::{clip, Exchange, Instance, Value};

/// The largest coordinate, radius or length accepted, mm (1000 km): a machine's part is
/// metres across, and the geometry's squared lengths stay far from overflow.
pub(crate) const MAX_MM: f64 = 1e9;

/// The range of a length unit, mm per unit: a nanometre to 1000 km. Outside it a unit is a
/// mistake (a factor of 1E300) or a hostile file, and every length would overflow or vanish.
pub(crate) const LENGTH_UNIT_MM: (f64, f64) = (1e-9, 1e9);

/// The range of a plane-angle unit, radians per unit: a microradian to 10 radians (the
/// radian, degree, grad and turn-based units of real files lie inside).
pub(crate) const ANGLE_UNIT_RAD: (f64, f64) = (1e-6, 10.0);

/// A right-handed frame: origin, unit axes `x`, `y = z x x`, `z`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Frame {
    /// Origin, mm.
    pub origin: Point3<f64>,
    /// Unit x axis (the reference direction).
    pub x: Vector3<f64>,
    /// Unit y axis.
    pub y: Vector3<f64>,
    /// Unit z axis (the placement's axis).
    pub z: Vector3<f64>,
}

/// The units of a file: factors that bring its lengths to mm and its plane angles to radians.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Units {
    /// Millimetres per file length unit (25.4 for inch, 10 for cm).
    pub mm_per_length: f64,
    /// Radians per file plane-angle unit (pi/180 for degree).
    pub rad_per_angle: f64,
    /// The length unit's name (`mm`, `inch`, `cm`, ...).
    pub length_name: &'static str,
}

impl Default for Units {
    fn default() -> Self {
        Self {
            mm_per_length: 1.0,
            rad_per_angle: 1.0,
            length_name: "mm",
        }
    }
}

/// A quantity of work the reader counts against a budget ([`Charge::limit`]).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[non_exhaustive]
pub enum Charge {
    /// Curve segments produced for contours (composites expanded).
    Segments,
    /// Control points of the curves read (contours and face edges).
    CurvePoints,
    /// Control points of the surfaces read.
    SurfacePoints,
    /// Points projected onto surfaces: face boundary samples, contour samples tested
    /// against faces.
    FaceTests,
}

impl Charge {
    /// The budget: far above a real part (docs/step.md), far below what exhausts the machine.
    pub fn limit(self) -> u64 {
        match self {
            Charge::Segments => 1_000_000,
            Charge::CurvePoints => 4_000_000,
            Charge::SurfacePoints => 10_000_000,
            Charge::FaceTests => 10_000_000,
        }
    }

    /// What is counted, for the budget's error message.
    pub fn what(self) -> &'static str {
        match self {
            Charge::Segments => "contour segments",
            Charge::CurvePoints => "curve control points",
            Charge::SurfacePoints => "surface control points",
            Charge::FaceTests => "points projected onto faces",
        }
    }
}

/// The work an import did, counted against the reader's budgets: what a test holds a hostile
/// file to, and what a user reads to see where an import's time went.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
#[non_exhaustive]
pub struct Work {
    /// Entity instances in the file (each parsed once for the syntax check).
    pub instances: u64,
    /// Curve segments produced for contours.
    pub segments: u64,
    /// Control points of the curves read.
    pub curve_points: u64,
    /// Control points of the surfaces read.
    pub surface_points: u64,
    /// Points projected onto surfaces (face boundaries, contour samples against faces).
    pub face_tests: u64,
}

/// The entity table with the file's units applied on access.
pub(crate) struct Model<'a> {
    /// The parsed file.
    pub(crate) ex: &'a Exchange<'a>,
    /// Its units.
    pub(crate) units: Units,
    /// What was assumed about the units (a file with no unit context).
    pub(crate) warnings: Vec<String>,
    /// The file's length uncertainty (its `UNCERTAINTY_MEASURE_WITH_UNIT` of a length, the
    /// largest if it gives several), mm: how far apart two points may be and still be one
    /// for the system that wrote it.
    pub(crate) uncertainty_mm: Option<f64>,
    /// The work done so far, per [`Charge`].
    spent: [std::cell::Cell<u64>; 4],
}

/// Builds the error of an entity.
/// The evaluator's refusal of an entity's numbers, keeping it as the source.
pub(crate) fn geometry_err(inst: &Instance, source: kerf_nurbs::NurbsError) -> StepError {
    StepError::Geometry {
        id: inst.id,
        name: clip(&inst.name()),
        source: Box::new(source),
    }
}

pub(crate) fn err(inst: &Instance, message: impl Into<String>) -> StepError {
    StepError::Entity {
        id: inst.id,
        name: clip(&inst.name()),
        message: message.into(),
    }
}

impl<'a> Model<'a> {
    /// Wraps the table, reading the units.
    pub(crate) fn new(ex: &'a Exchange<'a>) -> Result<Self> {
        let (units, mut warnings) = read_units(ex)?;
        let uncertainty_mm = read_uncertainty(ex, &mut warnings)?;
        Ok(Self {
            ex,
            units,
            warnings,
            uncertainty_mm,
            spent: Default::default(),
        })
    }

    /// Counts `n` units of `what` on behalf of `inst`, refusing the file once the total
    /// passes the budget (checked before the work is done, so the budget bounds it).
    pub(crate) fn charge(&self, inst: &Instance, what: Charge, n: usize) -> Result<()> {
        let cell = &self.spent[what as usize];
        let total = cell.get().saturating_add(n as u64);
        cell.set(total);
        if total > what.limit() {
            return Err(StepError::Budget {
                what: what.what().into(),
                limit: what.limit(),
                place: format!("#{} {}", inst.id, clip(&inst.name())),
            });
        }
        Ok(())
    }

    /// The work counted so far.
    pub(crate) fn work(&self) -> Work {
        let get = |c: Charge| self.spent[c as usize].get();
        Work {
            instances: self.ex.len() as u64,
            segments: get(Charge::Segments),
            curve_points: get(Charge::CurvePoints),
            surface_points: get(Charge::SurfacePoints),
            face_tests: get(Charge::FaceTests),
        }
    }

    /// The instance `#id` (parsed from the file's text now: keep it while you use it), or an
    /// error on `from` naming the dangling reference.
    pub(crate) fn get(&self, from: &Instance, id: u64) -> Result<Instance> {
        lookup(self.ex, from, id)
    }

    /// A length parameter in mm: the file's number times its unit, finite and at most
    /// [`MAX_MM`] in size.
    pub(crate) fn length(&self, inst: &Instance, v: Option<&Value>, what: &str) -> Result<f64> {
        let x = real(inst, v, what)? * self.units.mm_per_length;
        if !(x.abs() <= MAX_MM) {
            return Err(err(
                inst,
                format!("{what} is {x:e} mm, beyond the {MAX_MM:e} mm kerf accepts"),
            ));
        }
        Ok(x)
    }

    /// The parameters of record `name` of `inst`.
    pub(crate) fn rec<'b>(&self, inst: &'b Instance, name: &str) -> Result<&'b [Value]> {
        inst.record(name)
            .ok_or_else(|| err(inst, format!("expected a {name}")))
    }

    /// The instance referred to by parameter `k` of `params`.
    pub(crate) fn param_ref(
        &self,
        inst: &Instance,
        params: &[Value],
        k: usize,
    ) -> Result<Instance> {
        match params.get(k) {
            Some(Value::Ref(id)) => self.get(inst, *id),
            other => Err(err(
                inst,
                format!(
                    "parameter {} must be a reference, found {}",
                    k + 1,
                    show(other)
                ),
            )),
        }
    }

    /// A `CARTESIAN_POINT` in mm (2D points get z = 0).
    pub(crate) fn point(&self, inst: &Instance) -> Result<Point3<f64>> {
        let p = self.rec(inst, "CARTESIAN_POINT")?;
        let c = list(inst, p.get(1), "coordinates")?;
        if !(2..=3).contains(&c.len()) {
            return Err(err(
                inst,
                format!("expected 2 or 3 coordinates, found {}", c.len()),
            ));
        }
        let mut xyz = [0.0; 3];
        for (k, v) in c.iter().enumerate() {
            xyz[k] = self.length(inst, Some(v), &format!("coordinates[{k}]"))?;
        }
        Ok(Point3::from(xyz))
    }

    /// A `DIRECTION`, normalised.
    pub(crate) fn direction(&self, inst: &Instance) -> Result<Vector3<f64>> {
        let p = self.rec(inst, "DIRECTION")?;
        let c = reals(inst, p.get(1), "direction ratios")?;
        let v = match c.as_slice() {
            [x, y, z] => Vector3::new(*x, *y, *z),
            [x, y] => Vector3::new(*x, *y, 0.0),
            _ => {
                return Err(err(
                    inst,
                    format!("expected 2 or 3 ratios, found {}", c.len()),
                ))
            }
        };
        let n = v.norm();
        if !(n > 1e-300) || !n.is_finite() {
            return Err(err(inst, "zero direction"));
        }
        Ok(v / n)
    }

    /// A `VECTOR`: unit direction and magnitude in mm.
    pub(crate) fn vector(&self, inst: &Instance) -> Result<(Vector3<f64>, f64)> {
        let p = self.rec(inst, "VECTOR")?;
        let d = self.direction(&self.param_ref(inst, p, 1)?)?;
        let m = self.length(inst, p.get(2), "magnitude")?;
        if !(m > 0.0) {
            return Err(err(inst, format!("magnitude must be > 0, found {m}")));
        }
        Ok((d, m))
    }

    /// An `AXIS2_PLACEMENT_3D` (or `_2D`) as a frame. Without a reference direction, or with
    /// one parallel to the axis, the x axis is chosen as Open CASCADE's `gp_Ax2(P, N)` does,
    /// so that angles measured from it agree with the files' other readers.
    pub(crate) fn placement(&self, inst: &Instance) -> Result<Frame> {
        if let Some(p) = inst.record("AXIS2_PLACEMENT_2D") {
            let origin = self.point(&self.param_ref(inst, p, 1)?)?;
            let x = match p.get(2) {
                Some(Value::Ref(_)) => self.direction(&self.param_ref(inst, p, 2)?)?,
                _ => Vector3::x(),
            };
            let z = Vector3::z();
            return Ok(Frame {
                origin,
                x,
                y: z.cross(&x),
                z,
            });
        }
        let p = self.rec(inst, "AXIS2_PLACEMENT_3D")?;
        let origin = self.point(&self.param_ref(inst, p, 1)?)?;
        let z = match p.get(2) {
            Some(Value::Ref(_)) => self.direction(&self.param_ref(inst, p, 2)?)?,
            _ => Vector3::z(),
        };
        let reference = match p.get(3) {
            Some(Value::Ref(_)) => Some(self.direction(&self.param_ref(inst, p, 3)?)?),
            _ => None,
        };
        let x = reference
            .map(|r| r - z * r.dot(&z))
            .filter(|x| x.norm() > 1e-12)
            .map_or_else(|| default_x(&z), |x| x.normalize());
        Ok(Frame {
            origin,
            x,
            y: z.cross(&x),
            z,
        })
    }

    /// Every instance that is (or contains) entity `name`, in file order.
    pub(crate) fn all(&self, name: &str) -> Result<Vec<Instance>> {
        all(self.ex, name)
    }
}

/// The instance `#id`, or an error on `from` naming the dangling reference.
fn lookup(ex: &Exchange<'_>, from: &Instance, id: u64) -> Result<Instance> {
    ex.get(id)?.ok_or_else(|| {
        err(
            from,
            format!("refers to #{id}, which the file does not define"),
        )
    })
}

/// Every instance of `ex` that is (or contains) entity `name`, in file order.
fn all(ex: &Exchange<'_>, name: &str) -> Result<Vec<Instance>> {
    ex.ids_of(name)
        .into_iter()
        .filter_map(|id| ex.get(id).transpose())
        .collect()
}

/// The x direction Open CASCADE's `gp_Ax2(P, N)` derives from the axis `n` alone: a unit
/// vector perpendicular to `n` with one coordinate zero, chosen from the smallest component.
pub(crate) fn default_x(n: &Vector3<f64>) -> Vector3<f64> {
    let (a, b, c) = (n.x, n.y, n.z);
    let (aa, ba, ca) = (a.abs(), b.abs(), c.abs());
    let d = if ba <= aa && ba <= ca {
        if aa > ca {
            Vector3::new(-c, 0.0, a)
        } else {
            Vector3::new(c, 0.0, -a)
        }
    } else if aa <= ba && aa <= ca {
        if ba > ca {
            Vector3::new(0.0, -c, b)
        } else {
            Vector3::new(0.0, c, -b)
        }
    } else if aa > ba {
        Vector3::new(-b, a, 0.0)
    } else {
        Vector3::new(b, -a, 0.0)
    };
    d.normalize()
}

/// A short description of a parameter for messages.
pub(crate) fn show(v: Option<&Value>) -> String {
    match v {
        None => "nothing".into(),
        Some(Value::Int(i)) => format!("{i}"),
        Some(Value::Real(r)) => format!("{r}"),
        Some(Value::Str(_)) => "a string".into(),
        Some(Value::Enum(e)) => format!(".{e}."),
        Some(Value::Ref(r)) => format!("#{r}"),
        Some(Value::List(l)) => format!("a list of {}", l.len()),
        Some(Value::Typed(t, _)) => format!("{t}(...)"),
        Some(Value::Null) => "$".into(),
        Some(Value::Derived) => "*".into(),
        Some(Value::Binary(_)) => "a binary".into(),
    }
}

/// A number (integer or real, possibly typed like `LENGTH_MEASURE(2.)`).
pub(crate) fn real(inst: &Instance, v: Option<&Value>, what: &str) -> Result<f64> {
    match v {
        Some(Value::Real(r)) => Ok(*r),
        Some(Value::Int(i)) => Ok(*i as f64),
        Some(Value::Typed(_, inner)) => real(inst, Some(inner), what),
        other => Err(err(
            inst,
            format!("{what} must be a number, found {}", show(other)),
        )),
    }
}

/// A non-negative integer.
pub(crate) fn int(inst: &Instance, v: Option<&Value>, what: &str) -> Result<usize> {
    match v {
        Some(Value::Int(i)) if *i >= 0 => Ok(*i as usize),
        other => Err(err(
            inst,
            format!(
                "{what} must be a non-negative integer, found {}",
                show(other)
            ),
        )),
    }
}

/// A list parameter.
pub(crate) fn list<'v>(inst: &Instance, v: Option<&'v Value>, what: &str) -> Result<&'v [Value]> {
    match v {
        Some(Value::List(l)) => Ok(l),
        other => Err(err(
            inst,
            format!("{what} must be a list, found {}", show(other)),
        )),
    }
}

/// A list of numbers.
pub(crate) fn reals(inst: &Instance, v: Option<&Value>, what: &str) -> Result<Vec<f64>> {
    list(inst, v, what)?
        .iter()
        .enumerate()
        .map(|(k, x)| real(inst, Some(x), &format!("{what}[{k}]")))
        .collect()
}

/// A list of references.
pub(crate) fn refs(inst: &Instance, v: Option<&Value>, what: &str) -> Result<Vec<u64>> {
    list(inst, v, what)?
        .iter()
        .enumerate()
        .map(|(k, x)| match x {
            Value::Ref(r) => Ok(*r),
            other => Err(err(
                inst,
                format!(
                    "{what}[{k}] must be a reference, found {}",
                    show(Some(other))
                ),
            )),
        })
        .collect()
}

/// A boolean `.T.` / `.F.`.
pub(crate) fn boolean(inst: &Instance, v: Option<&Value>, what: &str) -> Result<bool> {
    match v {
        Some(Value::Enum(e)) if e == "T" => Ok(true),
        Some(Value::Enum(e)) if e == "F" => Ok(false),
        other => Err(err(
            inst,
            format!("{what} must be .T. or .F., found {}", show(other)),
        )),
    }
}

/// The instance's name attribute (the first string parameter of its representation item), or
/// the empty string.
pub(crate) fn name_of(inst: &Instance) -> String {
    for (_, p) in &inst.records {
        if let Some(Value::Str(s)) = p.first() {
            return s.clone();
        }
    }
    String::new()
}

/// What a unit measures.
#[derive(Debug, Clone, Copy, PartialEq)]
enum Kind {
    /// Lengths: an SI metre or a conversion of a length unit; mm per unit.
    Length,
    /// Plane angles: an SI radian or a conversion of an angle unit; radians per unit.
    Angle,
}

impl Kind {
    fn si_name(self) -> &'static str {
        match self {
            Kind::Length => "METRE",
            Kind::Angle => "RADIAN",
        }
    }

    fn entity(self) -> &'static str {
        match self {
            Kind::Length => "LENGTH_UNIT",
            Kind::Angle => "PLANE_ANGLE_UNIT",
        }
    }
}

/// The file's length uncertainty in mm: the largest `UNCERTAINTY_MEASURE_WITH_UNIT` whose
/// value is a `LENGTH_MEASURE` (or `POSITIVE_LENGTH_MEASURE`), in the length unit it
/// references, among those a `GLOBAL_UNCERTAINTY_ASSIGNED_CONTEXT` names (a stray one is not
/// the file's). The value and unit are read from the instance's `MEASURE_WITH_UNIT` part where
/// it is a complex instance. A length uncertainty whose value or unit cannot be read, or that
/// is not a finite number > 0 in mm, is left out with a warning; other measures (angles) are
/// not lengths and are passed over.
fn read_uncertainty(ex: &Exchange<'_>, warnings: &mut Vec<String>) -> Result<Option<f64>> {
    let mut named: Vec<u64> = Vec::new();
    for ctx in all(ex, "GLOBAL_UNCERTAINTY_ASSIGNED_CONTEXT")? {
        if let Some(Value::List(items)) = ctx
            .record("GLOBAL_UNCERTAINTY_ASSIGNED_CONTEXT")
            .and_then(|p| p.first())
        {
            named.extend(items.iter().filter_map(|v| match v {
                Value::Ref(id) => Some(*id),
                _ => None,
            }));
        }
    }
    let mut largest: Option<f64> = None;
    for inst in all(ex, "UNCERTAINTY_MEASURE_WITH_UNIT")? {
        if !named.contains(&inst.id) {
            continue;
        }
        // The simple entity carries value and unit first; a complex instance carries them in
        // its MEASURE_WITH_UNIT part.
        let p = [
            inst.record("UNCERTAINTY_MEASURE_WITH_UNIT"),
            inst.record("MEASURE_WITH_UNIT"),
        ]
        .into_iter()
        .flatten()
        .find(|p| matches!(p.first(), Some(Value::Typed(..))))
        .unwrap_or(&[]);
        let value = match p.first() {
            Some(Value::Typed(name, v))
                if name == "LENGTH_MEASURE" || name == "POSITIVE_LENGTH_MEASURE" =>
            {
                match **v {
                    Value::Real(r) => r,
                    Value::Int(i) => i as f64,
                    _ => f64::NAN,
                }
            }
            _ => continue,
        };
        let unit = match p.get(1) {
            Some(Value::Ref(id)) => ex.get(*id)?,
            _ => None,
        };
        let factor = unit
            .as_ref()
            .and_then(|u| unit_factor(ex, u, Kind::Length, 0).ok())
            .map(|(f, _)| f);
        match factor {
            Some(f) if value.is_finite() && (value * f).is_finite() && value * f > 0.0 => {
                largest = Some(largest.map_or(value * f, |l: f64| l.max(value * f)));
            }
            _ => warnings.push(format!(
                "#{} UNCERTAINTY_MEASURE_WITH_UNIT: its length ({value}) or its unit cannot be read: the file's edge tolerance is not taken from it",
                inst.id
            )),
        }
    }
    Ok(largest)
}

/// The units of the geometry: from every `GLOBAL_UNIT_ASSIGNED_CONTEXT`, which must agree.
/// A file with none is read in mm and radians, and the assumption is returned as a warning.
fn read_units(ex: &Exchange<'_>) -> Result<(Units, Vec<String>)> {
    let mut found: Option<(Units, u64)> = None;
    let mut warnings = Vec::new();
    for inst in all(ex, "GLOBAL_UNIT_ASSIGNED_CONTEXT")? {
        let p = inst.record("GLOBAL_UNIT_ASSIGNED_CONTEXT").unwrap_or(&[]);
        let mut u = Units::default();
        let mut length_given = false;
        let mut angle_given = false;
        for uid in refs(&inst, p.first(), "units")? {
            let unit = lookup(ex, &inst, uid)?;
            let kind = match (unit.is("LENGTH_UNIT"), unit.is("PLANE_ANGLE_UNIT")) {
                (true, false) => Kind::Length,
                (false, true) => Kind::Angle,
                (true, true) => {
                    return Err(err(
                        &unit,
                        "a unit cannot be both a LENGTH_UNIT and a PLANE_ANGLE_UNIT",
                    ))
                }
                (false, false) => continue,
            };
            let (f, name) = unit_factor(ex, &unit, kind, 0)?;
            // One context, one unit of each kind: with two, which one the geometry means is a
            // guess (the last listed won, silently: mm and inch gave a 25.4 x error either way).
            let twice = |what: &str| {
                err(
                    &inst,
                    format!(
                        "lists a second {what} unit (#{uid}); a context has one unit of each kind"
                    ),
                )
            };
            match kind {
                Kind::Length => {
                    if length_given {
                        return Err(twice("length"));
                    }
                    u.mm_per_length = f;
                    u.length_name = name;
                    length_given = true;
                }
                Kind::Angle => {
                    if angle_given {
                        return Err(twice("plane angle"));
                    }
                    u.rad_per_angle = f;
                    angle_given = true;
                }
            }
        }
        if !length_given {
            warnings.push(format!(
                "#{} GLOBAL_UNIT_ASSIGNED_CONTEXT names no length unit: lengths read as mm",
                inst.id
            ));
        }
        match found {
            Some((prev, pid))
                if (prev.mm_per_length - u.mm_per_length).abs() > 1e-12 * prev.mm_per_length
                    || (prev.rad_per_angle - u.rad_per_angle).abs() > 1e-12 =>
            {
                return Err(err(
                    &inst,
                    format!(
                        "its units ({} mm per length unit) differ from those of #{pid} ({} mm); \
                         files with several unit systems are not supported",
                        u.mm_per_length, prev.mm_per_length
                    ),
                ));
            }
            Some(_) => {}
            None => found = Some((u, inst.id)),
        }
    }
    if found.is_none() {
        warnings.push(
            "the file has no GLOBAL_UNIT_ASSIGNED_CONTEXT: lengths read as mm and angles as \
             radians (an inch or metre file without its units would come out 25.4 or 1000 \
             times too small)"
                .into(),
        );
    }
    Ok((found.map(|f| f.0).unwrap_or_default(), warnings))
}

/// mm per unit for a length unit, radians per unit for a plane-angle unit, and a name. The
/// unit must measure `kind` (an SI unit of the kind's base, or a conversion of such a unit),
/// its SI prefix must be an enumeration, and the factor must lie in the kind's range.
fn unit_factor(
    ex: &Exchange<'_>,
    unit: &Instance,
    kind: Kind,
    depth: usize,
) -> Result<(f64, &'static str)> {
    if depth > 8 {
        return Err(err(unit, "conversion-based units nested too deeply"));
    }
    // A unit that says what it measures must say the kind it is used for.
    for other in [Kind::Length, Kind::Angle] {
        if other != kind && unit.is(other.entity()) {
            return Err(err(
                unit,
                format!(
                    "is a {} where a {} is needed",
                    other.entity(),
                    kind.entity()
                ),
            ));
        }
    }
    let (f, name) = if let Some(p) = unit.record("SI_UNIT") {
        let prefix_name = match p.first() {
            Some(Value::Enum(e)) => Some(e.as_str()),
            None | Some(Value::Null | Value::Derived) => None,
            Some(other) => {
                return Err(err(
                    unit,
                    format!(
                        "SI prefix must be an enumeration like .MILLI. or $, found {}",
                        show(Some(other))
                    ),
                ))
            }
        };
        let prefix = match prefix_name {
            None => 1.0,
            Some("MILLI") => 1e-3,
            Some("CENTI") => 1e-2,
            Some("DECI") => 1e-1,
            Some("KILO") => 1e3,
            Some("MICRO") => 1e-6,
            Some("NANO") => 1e-9,
            Some("DECA") => 1e1,
            Some("HECTO") => 1e2,
            Some(other) => {
                return Err(err(
                    unit,
                    format!("SI prefix .{}. is not supported", clip(other)),
                ))
            }
        };
        match p.get(1) {
            Some(Value::Enum(e)) if e == kind.si_name() => match kind {
                Kind::Length => (
                    prefix * 1e3,
                    match prefix_name {
                        Some("MILLI") => "mm",
                        Some("CENTI") => "cm",
                        Some("MICRO") => "um",
                        Some("KILO") => "km",
                        None => "m",
                        _ => "converted",
                    },
                ),
                Kind::Angle => (prefix, "rad"),
            },
            Some(Value::Enum(e)) if e == "METRE" || e == "RADIAN" => {
                return Err(err(
                    unit,
                    format!(
                        "a {} must be based on the {}, found .{e}.",
                        kind.entity(),
                        kind.si_name().to_ascii_lowercase()
                    ),
                ))
            }
            other => return Err(err(unit, format!("unit {} is not supported", show(other)))),
        }
    } else if let Some(p) = unit.record("CONVERSION_BASED_UNIT") {
        let label = match p.first() {
            Some(Value::Str(s)) => s.to_ascii_lowercase(),
            _ => String::new(),
        };
        let Some(Value::Ref(mid)) = p.get(1) else {
            return Err(err(unit, "conversion-based unit without a measure"));
        };
        let m = lookup(ex, unit, *mid)?;
        let mp = m
            .records
            .iter()
            .find(|(n, _)| n.ends_with("MEASURE_WITH_UNIT"))
            .map(|(_, p)| p.as_slice())
            .ok_or_else(|| err(&m, "expected a MEASURE_WITH_UNIT"))?;
        let value = real(&m, mp.first(), "value_component")?;
        let Some(Value::Ref(base)) = mp.get(1) else {
            return Err(err(&m, "unit_component must be a reference"));
        };
        let b = lookup(ex, &m, *base)?;
        let (f, _) = unit_factor(ex, &b, kind, depth + 1)?;
        let name = match (kind, label.as_str()) {
            (Kind::Length, "inch" | "in") => "inch",
            (Kind::Length, "foot" | "ft") => "foot",
            (Kind::Angle, "degree" | "deg") => "degree",
            _ => "converted",
        };
        (value * f, name)
    } else {
        return Err(err(
            unit,
            "unit must be an SI_UNIT or a CONVERSION_BASED_UNIT",
        ));
    };
    let (lo, hi, what) = match kind {
        Kind::Length => (LENGTH_UNIT_MM.0, LENGTH_UNIT_MM.1, "mm"),
        Kind::Angle => (ANGLE_UNIT_RAD.0, ANGLE_UNIT_RAD.1, "rad"),
    };
    if !(f >= lo && f <= hi) {
        return Err(err(
            unit,
            format!(
                "a {} of {f:e} {what} is outside the range {lo:e} to {hi:e} {what} kerf accepts",
                kind.entity()
            ),
        ));
    }
    Ok((f, name))
}
