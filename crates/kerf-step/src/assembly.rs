//! Assembly placements: where each face and geometric set lies in the file's root frame.
//!
//! A part's representation is placed into an assembly's by a `REPRESENTATION_RELATIONSHIP`
//! (`rep_1` the part's, `rep_2` the assembly's) with a `REPRESENTATION_RELATIONSHIP_WITH_
//! TRANSFORMATION` whose `ITEM_DEFINED_TRANSFORMATION` maps the placement `item_1` (in
//! `rep_1`) onto `item_2` (in `rep_2`): `x_2 = F(item_2) F(item_1)^-1 x_1`, `F` a placement's
//! frame as a rigid map (`x -> O + R x`). A relationship without a transformation (a part's
//! shape representation and its B-rep's) joins two representations in one frame. A
//! representation's placements are the products along every chain of relationships up to a
//! representation that is placed in no other: one per instance of the part (a part used twice
//! has two). A `MAPPED_ITEM` among a representation's items places its `REPRESENTATION_MAP`'s
//! representation into that one the same way, from `mapping_origin` onto `mapping_target`.

use std::collections::{HashMap, HashSet};

use nalgebra::{Matrix3, Vector3};

use crate::error::Result;
use crate::model::{err, refs, Frame, Model};
use crate::parser::Value;

/// The most instances of one representation an import takes (the product of the counts along a
/// chain: a hostile file of ten levels of ten instances asks for ten billion).
pub(crate) const MAX_INSTANCES: usize = 10_000;

/// The entities that relate two representations.
const RELATIONSHIP_KINDS: [&str; 3] = [
    "REPRESENTATION_RELATIONSHIP",
    "SHAPE_REPRESENTATION_RELATIONSHIP",
    "REPRESENTATION_RELATIONSHIP_WITH_TRANSFORMATION",
];

/// The most placed copies of faces and sets an import makes, summed over every
/// representation (a file of thousands of representations each placed ten thousand times
/// asked for gigabytes).
pub(crate) const MAX_PLACED: usize = 200_000;

/// The most control points the placed copies of faces may have in all (the surface-point
/// budget of the reader).
pub(crate) const MAX_PLACED_POINTS: usize = 10_000_000;

/// A representation's items: the list that is the second parameter of one of its records (a
/// complex representation may carry it in any of them).
fn items(rep: &crate::parser::Instance) -> Vec<u64> {
    rep.records
        .iter()
        .find(|(_, p)| matches!(p.get(1), Some(Value::List(_))))
        .and_then(|(_, p)| refs(rep, p.get(1), "items").ok())
        .unwrap_or_default()
}

/// The representation entities whose items a mapped item may be among.
const REPRESENTATION_KINDS: [&str; 9] = [
    "SHAPE_REPRESENTATION",
    "ADVANCED_BREP_SHAPE_REPRESENTATION",
    "MANIFOLD_SURFACE_SHAPE_REPRESENTATION",
    "GEOMETRICALLY_BOUNDED_WIREFRAME_SHAPE_REPRESENTATION",
    "GEOMETRICALLY_BOUNDED_SURFACE_SHAPE_REPRESENTATION",
    "FACETED_BREP_SHAPE_REPRESENTATION",
    "EDGE_BASED_WIREFRAME_SHAPE_REPRESENTATION",
    "SHELL_BASED_WIREFRAME_SHAPE_REPRESENTATION",
    "REPRESENTATION",
];

/// The deepest chain of placements (assemblies of assemblies) read.
pub(crate) const MAX_DEPTH: usize = 64;

/// A rigid map `x -> r x + t`, mm.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct Rigid {
    pub(crate) r: Matrix3<f64>,
    pub(crate) t: Vector3<f64>,
}

impl Rigid {
    fn identity() -> Self {
        Self {
            r: Matrix3::identity(),
            t: Vector3::zeros(),
        }
    }

    fn of(f: &Frame) -> Self {
        Self {
            r: Matrix3::from_columns(&[f.x, f.y, f.z]),
            t: f.origin.coords,
        }
    }

    fn inverse(&self) -> Self {
        let rt = self.r.transpose();
        Self {
            r: rt,
            t: -(rt * self.t),
        }
    }

    /// `self` after `inner`.
    fn after(&self, inner: &Rigid) -> Self {
        Self {
            r: self.r * inner.r,
            t: self.r * inner.t + self.t,
        }
    }

    /// Whether the map moves nothing (to rounding: 1e-12 in rotation, 1e-9 mm).
    pub(crate) fn is_identity(&self) -> bool {
        (self.r - Matrix3::identity()).abs().max() <= 1e-12 && self.t.norm() <= 1e-9
    }
}

/// Each face's and each geometric set's placements in the root frame, one per instance; an
/// entity absent from both maps lies where its coordinates put it (once).
#[derive(Debug, Default)]
pub(crate) struct Placements {
    pub(crate) faces: HashMap<u64, std::rc::Rc<Vec<Rigid>>>,
    pub(crate) sets: HashMap<u64, std::rc::Rc<Vec<Rigid>>>,
}

fn root(parent: &mut HashMap<u64, u64>, a: u64) -> u64 {
    let mut a = a;
    while let Some(&p) = parent.get(&a) {
        if p == a {
            break;
        }
        let g = parent.get(&p).copied().unwrap_or(p);
        parent.insert(a, g);
        a = p;
    }
    a
}

/// Puts `a` and `b` in one frame.
fn join(parent: &mut HashMap<u64, u64>, a: u64, b: u64) {
    let (a, b) = (root(parent, a), root(parent, b));
    if a != b {
        parent.insert(a.max(b), a.min(b));
    }
}

/// The placements of the file's faces and sets (see the module).
///
/// # Errors
/// A transformation that is not an `ITEM_DEFINED_TRANSFORMATION` between two placements, a cycle
/// of placements, chains deeper than [`MAX_DEPTH`], more than [`MAX_INSTANCES`] instances of
/// one representation or [`MAX_PLACED`] placements in all, a moving mapped item no
/// representation holds.
pub(crate) fn placements(m: &Model<'_>) -> Result<Placements> {
    // Representations in one frame (union-find) and the placements between frames.
    let mut parent: HashMap<u64, u64> = HashMap::new();
    // (child representation, parent representation, the map from the child's frame).
    let mut placed: Vec<(u64, u64, Rigid)> = Vec::new();
    // Every representation a relationship or a mapped item names (the walk below visits each).
    let mut named: Vec<u64> = Vec::new();
    // Relationships written alone (SHAPE_REPRESENTATION_RELATIONSHIP, ..._WITH_TRANSFORMATION)
    // or as one complex instance of several; each read once.
    for id in m.ex.ids_of_any(&RELATIONSHIP_KINDS) {
        let Some(inst) = m.ex.get(id)? else { continue };
        // rep_1 and rep_2: parameters 3 and 4 of whichever record carries the relationship's
        // own attributes.
        let Some(p) = RELATIONSHIP_KINDS
            .iter()
            .filter_map(|k| inst.record(k))
            .find(|p| p.len() >= 4)
        else {
            return Err(err(
                &inst,
                "a representation relationship without rep_1 and rep_2",
            ));
        };
        let (Some(Value::Ref(r1)), Some(Value::Ref(r2))) = (p.get(2), p.get(3)) else {
            return Err(err(&inst, "rep_1 and rep_2 must be references"));
        };
        // The transformation: the one parameter of the ..._WITH_TRANSFORMATION record of a
        // complex instance, or the fifth of a lone one.
        let op = match inst.record("REPRESENTATION_RELATIONSHIP_WITH_TRANSFORMATION") {
            None => None,
            Some(t) if t.len() == 1 => Some(m.param_ref(&inst, t, 0)?),
            Some(t) => Some(m.param_ref(&inst, t, 4)?),
        };
        named.extend([*r1, *r2]);
        match op {
            None => join(&mut parent, *r1, *r2),
            Some(op) => {
                let Some(it) = op.record("ITEM_DEFINED_TRANSFORMATION") else {
                    return Err(err(
                        &op,
                        "a placement that is not an ITEM_DEFINED_TRANSFORMATION (a transformation operator may scale or mirror): not read",
                    ));
                };
                let f1 = m.placement(&m.param_ref(&op, it, 2)?)?;
                let f2 = m.placement(&m.param_ref(&op, it, 3)?)?;
                placed.push((*r1, *r2, Rigid::of(&f2).after(&Rigid::of(&f1).inverse())));
            }
        }
    }
    // Mapped items: a MAPPED_ITEM in a representation's items places the items of its
    // REPRESENTATION_MAP's representation from `mapping_origin` at `mapping_target`.
    let mapped = m.all("MAPPED_ITEM")?;
    if !mapped.is_empty() {
        // Which representation holds each mapped item.
        let mut holder: HashMap<u64, Vec<u64>> = HashMap::new();
        for r in m.ex.ids_of_any(&REPRESENTATION_KINDS) {
            let Some(rep) = m.ex.get(r)? else { continue };
            for id in items(&rep) {
                holder.entry(id).or_default().push(rep.id);
            }
        }
        for inst in &mapped {
            let p = m.rec(inst, "MAPPED_ITEM")?;
            let map = m.param_ref(inst, p, 1)?;
            let mp = m.rec(&map, "REPRESENTATION_MAP")?;
            let origin = m.param_ref(&map, mp, 0)?;
            let Some(Value::Ref(source)) = mp.get(1) else {
                return Err(err(&map, "mapped_representation must be a reference"));
            };
            let target = m.param_ref(inst, p, 2)?;
            let is_placement = |i: &crate::parser::Instance| {
                i.record("AXIS2_PLACEMENT_3D").is_some() || i.record("AXIS2_PLACEMENT_2D").is_some()
            };
            if !is_placement(&origin) || !is_placement(&target) {
                return Err(err(
                    inst,
                    format!(
                        "places the items of #{} from #{} {} at #{} {}: only a placement onto a placement is read (a transformation operator may scale or mirror)",
                        map.id,
                        origin.id,
                        origin.name(),
                        target.id,
                        target.name()
                    ),
                ));
            }
            let t = Rigid::of(&m.placement(&target)?)
                .after(&Rigid::of(&m.placement(&origin)?).inverse());
            let Some(holders) = holder.get(&inst.id) else {
                if t.is_identity() {
                    continue; // in place: nothing moves
                }
                return Err(err(
                    inst,
                    format!(
                        "places the items of #{} from #{} at #{}, but no representation kerf knows holds it: where they go is not defined (export the part alone, or as one body in its place)",
                        map.id, origin.id, target.id
                    ),
                ));
            };
            for &h in holders {
                named.extend([*source, h]);
                placed.push((*source, h, t));
            }
        }
    }
    if placed.is_empty() {
        return Ok(Placements::default());
    }
    // Edges between frames (classes).
    let mut up: HashMap<u64, Vec<(u64, Rigid)>> = HashMap::new();
    for (c, p, t) in &placed {
        let (c, p) = (root(&mut parent, *c), root(&mut parent, *p));
        if c == p && t.is_identity() {
            continue; // a frame placed in place in itself (an in-place map of its own B-rep)
        }
        up.entry(c).or_default().push((p, *t));
    }
    // Each class's placements in the root frame, memoized (shared, not copied); a class on the
    // current chain again is a cycle; every placement made is counted against MAX_PLACED.
    type Shared = std::rc::Rc<Vec<Rigid>>;
    fn place(
        c: u64,
        up: &HashMap<u64, Vec<(u64, Rigid)>>,
        memo: &mut HashMap<u64, Shared>,
        chain: &mut Vec<u64>,
        made: &mut usize,
    ) -> std::result::Result<Shared, String> {
        if let Some(v) = memo.get(&c) {
            return Ok(v.clone());
        }
        if chain.contains(&c) {
            return Err("is placed in itself (a cycle of placements)".into());
        }
        if chain.len() >= MAX_DEPTH {
            return Err(format!(
                "is placed through assemblies more than {MAX_DEPTH} deep"
            ));
        }
        let out = match up.get(&c) {
            None => vec![Rigid::identity()],
            Some(edges) => {
                chain.push(c);
                let mut out = Vec::new();
                for (p, t) in edges {
                    for q in place(*p, up, memo, chain, made)?.iter() {
                        out.push(q.after(t));
                        *made += 1;
                        if out.len() > MAX_INSTANCES {
                            return Err(format!("has more than {MAX_INSTANCES} instances"));
                        }
                        if *made > MAX_PLACED {
                            return Err(format!(
                                "takes the file past {MAX_PLACED} placements of representations"
                            ));
                        }
                    }
                }
                chain.pop();
                out
            }
        };
        let out = std::rc::Rc::new(out);
        memo.insert(c, out.clone());
        Ok(out)
    }
    let mut memo = HashMap::new();
    let mut made = 0usize;
    let mut class_places: HashMap<u64, Shared> = HashMap::new();
    let mut reps: Vec<u64> = named;
    reps.sort_unstable();
    reps.dedup();
    for &r in &reps {
        let c = root(&mut parent, r);
        let v = match place(c, &up, &mut memo, &mut Vec::new(), &mut made) {
            Ok(v) => v,
            Err(why) => {
                return Err(match m.ex.get(r)? {
                    Some(i) => err(&i, format!("this representation {why}")),
                    None => crate::error::StepError::Entity {
                        id: r,
                        name: "REPRESENTATION".into(),
                        message: format!("this representation {why}"),
                    },
                });
            }
        };
        class_places.insert(r, v);
    }
    // The faces and sets each placed representation holds: its items, followed through the
    // references down to faces and sets (each instance visited once).
    let mut out = Placements::default();
    let mut seen: HashSet<u64> = HashSet::new();
    let mut copies = 0usize;
    for r in reps {
        let Some(v) = class_places.get(&r).cloned() else {
            continue;
        };
        if v.len() == 1 && v[0].is_identity() {
            continue;
        }
        let Some(rep) = m.ex.get(r)? else { continue };
        let mut stack: Vec<u64> = items(&rep);
        while let Some(id) = stack.pop() {
            if !seen.insert(id) {
                continue;
            }
            let Some(inst) = m.ex.get(id)? else { continue };
            let face = inst.is("ADVANCED_FACE") || inst.is("FACE_SURFACE");
            let set = inst.is("GEOMETRIC_SET") || inst.is("GEOMETRIC_CURVE_SET");
            if face || set {
                copies += v.len();
                if copies > MAX_PLACED {
                    return Err(err(
                        &inst,
                        format!(
                            "placing it takes the file past {MAX_PLACED} placed faces and sets"
                        ),
                    ));
                }
                if face {
                    out.faces.insert(id, v.clone());
                } else {
                    out.sets.insert(id, v.clone());
                }
                continue;
            }
            // Down through solids, shells and models to their faces; not into geometry.
            let through = [
                "MANIFOLD_SOLID_BREP",
                "BREP_WITH_VOIDS",
                "CLOSED_SHELL",
                "OPEN_SHELL",
                "ORIENTED_CLOSED_SHELL",
                "SHELL_BASED_SURFACE_MODEL",
                "FACE_BASED_SURFACE_MODEL",
                "CONNECTED_FACE_SET",
                "ORIENTED_FACE",
            ];
            if through.iter().any(|n| inst.is(n)) {
                for (_, ps) in &inst.records {
                    collect_refs(ps, &mut stack);
                }
            }
        }
    }
    Ok(out)
}

fn collect_refs(v: &[Value], out: &mut Vec<u64>) {
    for x in v {
        match x {
            Value::Ref(id) => out.push(*id),
            Value::List(l) => collect_refs(l, out),
            _ => {}
        }
    }
}

/// `x -> r x + t` on a point.
pub(crate) fn point(m: &Rigid, p: &nalgebra::Point3<f64>) -> nalgebra::Point3<f64> {
    nalgebra::Point3::from(m.r * p.coords + m.t)
}
