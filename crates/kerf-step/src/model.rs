//! Typed access to the entity table: references followed with errors naming the entity,
//! points and directions in millimetres, placements, and the file's units.

use nalgebra::{Point3, Vector3};

use crate::error::{Result, StepError};
use crate::parser::{Exchange, Instance, Value};

/// A right-handed frame: origin, unit axes `x`, `y = z x x`, `z`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct Frame {
    /// Origin, mm.
    pub(crate) origin: Point3<f64>,
    /// Unit x axis (the reference direction).
    pub(crate) x: Vector3<f64>,
    /// Unit y axis.
    pub(crate) y: Vector3<f64>,
    /// Unit z axis (the placement's axis).
    pub(crate) z: Vector3<f64>,
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

/// The entity table with the file's units applied on access.
pub(crate) struct Model<'a> {
    /// The parsed file.
    pub(crate) ex: &'a Exchange,
    /// Its units.
    pub(crate) units: Units,
}

/// Builds the error of an entity.
pub(crate) fn err(inst: &Instance, message: impl Into<String>) -> StepError {
    StepError::Entity {
        id: inst.id,
        name: inst.name(),
        message: message.into(),
    }
}

impl<'a> Model<'a> {
    /// Wraps the table, reading the units.
    pub(crate) fn new(ex: &'a Exchange) -> Result<Self> {
        let units = read_units(ex)?;
        Ok(Self { ex, units })
    }

    /// The instance `#id`, or an error on `from` naming the dangling reference.
    pub(crate) fn get(&self, from: &Instance, id: u64) -> Result<&'a Instance> {
        self.ex.instances.get(&id).ok_or_else(|| {
            err(
                from,
                format!("refers to #{id}, which the file does not define"),
            )
        })
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
    ) -> Result<&'a Instance> {
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
        let c = reals(inst, p.get(1), "coordinates")?;
        let s = self.units.mm_per_length;
        match c.as_slice() {
            [x, y, z] => Ok(Point3::new(x * s, y * s, z * s)),
            [x, y] => Ok(Point3::new(x * s, y * s, 0.0)),
            _ => Err(err(
                inst,
                format!("expected 2 or 3 coordinates, found {}", c.len()),
            )),
        }
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
        let d = self.direction(self.param_ref(inst, p, 1)?)?;
        let m = real(inst, p.get(2), "magnitude")? * self.units.mm_per_length;
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
            let origin = self.point(self.param_ref(inst, p, 1)?)?;
            let x = match p.get(2) {
                Some(Value::Ref(_)) => self.direction(self.param_ref(inst, p, 2)?)?,
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
        let origin = self.point(self.param_ref(inst, p, 1)?)?;
        let z = match p.get(2) {
            Some(Value::Ref(_)) => self.direction(self.param_ref(inst, p, 2)?)?,
            _ => Vector3::z(),
        };
        let reference = match p.get(3) {
            Some(Value::Ref(_)) => Some(self.direction(self.param_ref(inst, p, 3)?)?),
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
    pub(crate) fn all(&self, name: &str) -> Vec<&'a Instance> {
        self.ex
            .order
            .iter()
            .filter_map(|id| self.ex.instances.get(id))
            .filter(|i| i.is(name))
            .collect()
    }
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

/// The units of the geometry: from every `GLOBAL_UNIT_ASSIGNED_CONTEXT`, which must agree.
fn read_units(ex: &Exchange) -> Result<Units> {
    let mut found: Option<(Units, u64)> = None;
    for id in &ex.order {
        let inst = &ex.instances[id];
        let Some(p) = inst.record("GLOBAL_UNIT_ASSIGNED_CONTEXT") else {
            continue;
        };
        let mut u = Units::default();
        for uid in refs(inst, p.first(), "units")? {
            let unit = ex.instances.get(&uid).ok_or_else(|| {
                err(
                    inst,
                    format!("refers to #{uid}, which the file does not define"),
                )
            })?;
            if unit.is("LENGTH_UNIT") {
                let (f, name) = unit_factor(ex, unit, 0)?;
                u.mm_per_length = f;
                u.length_name = name;
            } else if unit.is("PLANE_ANGLE_UNIT") {
                u.rad_per_angle = unit_factor(ex, unit, 0)?.0;
            }
        }
        match found {
            Some((prev, pid))
                if (prev.mm_per_length - u.mm_per_length).abs() > 1e-12 * prev.mm_per_length
                    || (prev.rad_per_angle - u.rad_per_angle).abs() > 1e-12 =>
            {
                return Err(err(
                    inst,
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
    Ok(found.map(|f| f.0).unwrap_or_default())
}

/// For a length unit: mm per unit; for a plane-angle unit: radians per unit. Also a name.
fn unit_factor(ex: &Exchange, unit: &Instance, depth: usize) -> Result<(f64, &'static str)> {
    if depth > 8 {
        return Err(err(unit, "conversion-based units nested too deeply"));
    }
    if let Some(p) = unit.record("SI_UNIT") {
        let prefix = match p.first() {
            Some(Value::Enum(e)) => match e.as_str() {
                "MILLI" => 1e-3,
                "CENTI" => 1e-2,
                "DECI" => 1e-1,
                "KILO" => 1e3,
                "MICRO" => 1e-6,
                "NANO" => 1e-9,
                "DECA" => 1e1,
                "HECTO" => 1e2,
                other => return Err(err(unit, format!("SI prefix .{other}. is not supported"))),
            },
            _ => 1.0,
        };
        return match p.get(1) {
            Some(Value::Enum(e)) if e == "METRE" => Ok((
                prefix * 1e3,
                match p.first() {
                    Some(Value::Enum(e)) if e == "MILLI" => "mm",
                    Some(Value::Enum(e)) if e == "CENTI" => "cm",
                    Some(Value::Enum(e)) if e == "MICRO" => "um",
                    Some(Value::Enum(e)) if e == "KILO" => "km",
                    _ => "m",
                },
            )),
            Some(Value::Enum(e)) if e == "RADIAN" => Ok((prefix, "rad")),
            other => Err(err(unit, format!("unit {} is not supported", show(other)))),
        };
    }
    if let Some(p) = unit.record("CONVERSION_BASED_UNIT") {
        let label = match p.first() {
            Some(Value::Str(s)) => s.to_ascii_lowercase(),
            _ => String::new(),
        };
        let Some(Value::Ref(mid)) = p.get(1) else {
            return Err(err(unit, "conversion-based unit without a measure"));
        };
        let m = ex.instances.get(mid).ok_or_else(|| {
            err(
                unit,
                format!("refers to #{mid}, which the file does not define"),
            )
        })?;
        let mp = m
            .records
            .iter()
            .find(|(n, _)| n.ends_with("MEASURE_WITH_UNIT"))
            .map(|(_, p)| p.as_slice())
            .ok_or_else(|| err(m, "expected a MEASURE_WITH_UNIT"))?;
        let value = real(m, mp.first(), "value_component")?;
        let Some(Value::Ref(base)) = mp.get(1) else {
            return Err(err(m, "unit_component must be a reference"));
        };
        let b = ex.instances.get(base).ok_or_else(|| {
            err(
                m,
                format!("refers to #{base}, which the file does not define"),
            )
        })?;
        let (f, _) = unit_factor(ex, b, depth + 1)?;
        let name = match label.as_str() {
            "inch" | "in" => "inch",
            "foot" | "ft" => "foot",
            "degree" | "deg" => "degree",
            _ => "converted",
        };
        if !(value * f > 0.0) || !(value * f).is_finite() {
            return Err(err(
                unit,
                format!("conversion factor must be > 0, found {}", value * f),
            ));
        }
        return Ok((value * f, name));
    }
    Err(err(
        unit,
        "unit must be an SI_UNIT or a CONVERSION_BASED_UNIT",
    ))
}
