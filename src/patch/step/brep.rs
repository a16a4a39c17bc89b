//! From the Part 21 instance graph to faces: topology (`MANIFOLD_SOLID_BREP`,
//! `SHELL_BASED_SURFACE_MODEL`, shells, `ADVANCED_FACE` → bounds → `EDGE_LOOP` →
//! `ORIENTED_EDGE` → `EDGE_CURVE` → `VERTEX_POINT`), geometry (placements, curves, surfaces) and
//! units. Every entity the reader does not know is an [`StepError::Unsupported`] naming it and
//! its `#id`; wrong parameter counts or types are [`StepError::Invalid`]; parameters that do
//! not make an edge or surface are [`StepError::Geometry`].

use std::collections::{HashMap, HashSet};

use super::super::curve::Homogeneous;
use super::super::model::Patch;
use super::StepError;
use super::nurbs::{expand_knots, extract, hom, sub_curve};
use super::part21::{Instance, Part, Part21, Value};
use super::surface::{
    Frame, ParamMap, Surface, UvPatch, conic_angle, conic_pieces, detect_periods, frame,
    invert_curve, next_turn, unit,
};
use crate::base::vec3::{dot, norm, sub};

/// Piecewise Bézier curve with parameter ranges.
pub type Pieces = Vec<(f64, f64, Vec<Homogeneous>)>;

/// A 3D curve as STEP defines it.
#[derive(Clone, Debug)]
pub enum Curve {
    /// `p + t d`.
    Line([f64; 3], [f64; 3]),
    /// `o + a cos θ x + b sin θ y` (circle: `a = b`).
    Conic(Frame, f64, f64),
    /// A B-spline as Bézier pieces; `closed` if it ends where it starts.
    Pieces(Pieces, bool),
    /// A trimmed curve: its basis, and whether it runs in the basis's direction.
    Trimmed(Box<Curve>, bool),
}

/// One edge use in a loop.
#[derive(Clone, Copy, Debug)]
pub struct EdgeUse {
    /// The `EDGE_CURVE` id.
    pub edge: u64,
    /// Traversed from its start vertex to its end vertex.
    pub forward: bool,
}

/// A face read from the file.
#[derive(Clone, Debug)]
pub struct RawFace {
    /// `#id` of the face.
    pub id: u64,
    /// Its surface.
    pub surface: Surface,
    /// `same_sense`.
    pub same_sense: bool,
    /// `#id` of the surface (pcurves name it as their basis surface).
    pub surface_id: u64,
    /// Radians per file unit of the surface's `u` and `v` as pcurves give them (the file's
    /// plane-angle unit for angles, 1 for lengths and B-spline parameters); `None` where this
    /// reader's `(u, v)` is not the file's (surfaces of revolution and extrusion), so pcurves
    /// cannot be used.
    pub pcurve_units: Option<[f64; 2]>,
    /// Loops of edge uses, oriented as the face boundary (face on the left seen from the
    /// face normal).
    pub loops: Vec<Vec<EdgeUse>>,
}

/// Topology counts for `gwn info`.
#[derive(Clone, Debug, Default)]
pub struct Topology {
    /// Solids (`MANIFOLD_SOLID_BREP`).
    pub solids: usize,
    /// Shells.
    pub shells: usize,
    /// The length unit, e.g. `CENTI METRE`, or `unknown`.
    pub length_unit: String,
}

pub(crate) struct Reader<'a> {
    file: &'a Part21,
    angle_factor: f64,
    curves: HashMap<u64, Curve>,
    /// Edge geometry from start to end vertex, by `EDGE_CURVE` id.
    pub edges: HashMap<u64, Vec<Vec<Homogeneous>>>,
    /// The pcurves of each `EDGE_CURVE` that the reader can use, by edge id.
    pub pcurves: HashMap<u64, Vec<EdgePcurve>>,
    /// Pcurves the file gives that the reader cannot use (their 2D curve or the edge's 3D curve
    /// is of a kind without a parameter range here): those edge uses are mapped from 3D.
    pub pcurves_unreadable: usize,
}

/// A 2D curve of a pcurve, in the file's `(u, v)` units.
#[derive(Clone, Debug)]
pub enum Curve2 {
    /// `p + t d`.
    Line([f64; 2], [f64; 2]),
    /// `o + a cos θ x + b sin θ y`, `θ = t ×` the plane-angle factor (circle: `a = b`).
    Conic {
        /// Centre.
        o: [f64; 2],
        /// First axis (unit).
        x: [f64; 2],
        /// Second axis (unit, `x` turned by +90°).
        y: [f64; 2],
        /// Semi-axes.
        a: f64,
        /// Second semi-axis.
        b: f64,
        /// Radians per unit of `t`.
        angle: f64,
    },
    /// A B-spline as Bézier pieces (the third coordinate 0).
    Pieces(Pieces),
}

impl Curve2 {
    /// The point at the curve's own parameter `t` (B-splines clamped to their domain).
    pub fn at(&self, t: f64) -> [f64; 2] {
        match self {
            Curve2::Line(p, d) => [p[0] + t * d[0], p[1] + t * d[1]],
            Curve2::Conic {
                o,
                x,
                y,
                a,
                b,
                angle,
            } => {
                let (s, c) = (t * angle).sin_cos();
                [
                    o[0] + a * c * x[0] + b * s * y[0],
                    o[1] + a * c * x[1] + b * s * y[1],
                ]
            }
            Curve2::Pieces(p) => {
                let q = super::surface::curve_point(p, t);
                [q[0], q[1]]
            }
        }
    }
}

/// A pcurve of an edge: its 2D curve on the surface `#surface` and the parameter range of the
/// edge, from its start vertex to its end vertex (the 3D curve's parameters, which a
/// `SURFACE_CURVE`'s pcurves share, ISO 10303-42).
#[derive(Clone, Debug)]
pub struct EdgePcurve {
    /// `#id` of the basis surface.
    pub surface: u64,
    /// The 2D curve.
    pub curve: Curve2,
    /// Parameter at the edge's start and end vertex.
    pub range: [f64; 2],
}

fn invalid(id: u64, inst: &Instance, message: impl Into<String>) -> StepError {
    StepError::Invalid {
        id,
        entity: inst.display_name(),
        message: message.into(),
    }
}

fn geometry(id: u64, inst: &Instance, message: impl Into<String>) -> StepError {
    StepError::Geometry {
        id,
        entity: inst.display_name(),
        message: message.into(),
    }
}

fn unsupported(id: u64, inst: &Instance, context: &str) -> StepError {
    StepError::Unsupported {
        id,
        entity: inst.display_name(),
        context: context.to_string(),
    }
}

/// Parameter accessors with errors naming the entity.
struct Params<'a> {
    id: u64,
    inst: &'a Instance,
    part: &'a Part,
}

impl<'a> Params<'a> {
    fn get(&self, i: usize) -> Result<&'a Value, StepError> {
        self.part.params.get(i).ok_or_else(|| {
            invalid(
                self.id,
                self.inst,
                format!("{} has no parameter {}", self.part.name, i + 1),
            )
        })
    }
    fn real(&self, i: usize) -> Result<f64, StepError> {
        real_of(self.get(i)?).ok_or_else(|| self.bad(i, "a number"))
    }
    fn int(&self, i: usize) -> Result<i64, StepError> {
        match self.get(i)? {
            Value::Int(k) => Ok(*k),
            _ => Err(self.bad(i, "an integer")),
        }
    }
    fn refid(&self, i: usize) -> Result<u64, StepError> {
        match self.get(i)? {
            Value::Ref(r) => Ok(*r),
            _ => Err(self.bad(i, "a reference")),
        }
    }
    fn opt_ref(&self, i: usize) -> Result<Option<u64>, StepError> {
        match self.get(i)? {
            Value::Ref(r) => Ok(Some(*r)),
            Value::Null => Ok(None),
            _ => Err(self.bad(i, "a reference or $")),
        }
    }
    fn boolean(&self, i: usize) -> Result<bool, StepError> {
        match self.get(i)? {
            Value::Enum(e) if e == "T" => Ok(true),
            Value::Enum(e) if e == "F" => Ok(false),
            _ => Err(self.bad(i, ".T. or .F.")),
        }
    }
    fn list(&self, i: usize) -> Result<&'a [Value], StepError> {
        match self.get(i)? {
            Value::List(l) => Ok(l),
            _ => Err(self.bad(i, "a list")),
        }
    }
    fn refs(&self, i: usize) -> Result<Vec<u64>, StepError> {
        self.list(i)?
            .iter()
            .map(|v| match v {
                Value::Ref(r) => Ok(*r),
                _ => Err(self.bad(i, "a list of references")),
            })
            .collect()
    }
    fn reals(&self, i: usize) -> Result<Vec<f64>, StepError> {
        self.list(i)?
            .iter()
            .map(|v| real_of(v).ok_or_else(|| self.bad(i, "a list of numbers")))
            .collect()
    }
    fn ints(&self, i: usize) -> Result<Vec<i64>, StepError> {
        self.list(i)?
            .iter()
            .map(|v| match v {
                Value::Int(k) => Ok(*k),
                _ => Err(self.bad(i, "a list of integers")),
            })
            .collect()
    }
    fn bad(&self, i: usize, what: &str) -> StepError {
        invalid(
            self.id,
            self.inst,
            format!("{} parameter {} is not {what}", self.part.name, i + 1),
        )
    }
}

fn real_of(v: &Value) -> Option<f64> {
    match v {
        Value::Real(r) if r.is_finite() => Some(*r),
        Value::Int(k) => Some(*k as f64),
        Value::Typed(_, inner) if inner.len() == 1 => real_of(&inner[0]),
        _ => None,
    }
}

impl<'a> Reader<'a> {
    pub(crate) fn new(file: &'a Part21) -> Reader<'a> {
        let mut r = Reader {
            file,
            angle_factor: 1.0,
            curves: HashMap::new(),
            edges: HashMap::new(),
            pcurves: HashMap::new(),
            pcurves_unreadable: 0,
        };
        r.angle_factor = r.find_angle_factor();
        r
    }

    fn inst(&self, from: u64, id: u64) -> Result<&'a Instance, StepError> {
        self.file.instances.get(&id).ok_or(StepError::Dangling {
            id: from,
            target: id,
        })
    }

    /// The single part of a simple entity named one of `names`.
    fn simple(
        &self,
        from: u64,
        id: u64,
        names: &[&str],
        context: &str,
    ) -> Result<Params<'a>, StepError> {
        let inst = self.inst(from, id)?;
        match inst.parts.as_slice() {
            [part] if names.contains(&part.name.as_str()) => Ok(Params { id, inst, part }),
            _ => Err(unsupported(id, inst, context)),
        }
    }

    /// Radians per unit of the file's plane angles: the `CONVERSION_BASED_UNIT` of the
    /// `PLANE_ANGLE_UNIT` listed in a `GLOBAL_UNIT_ASSIGNED_CONTEXT` (1 when absent).
    fn find_angle_factor(&self) -> f64 {
        for id in &self.file.order {
            let inst = &self.file.instances[id];
            let Some(ctx) = inst.part("GLOBAL_UNIT_ASSIGNED_CONTEXT") else {
                continue;
            };
            let Some(Value::List(units)) = ctx.params.first() else {
                continue;
            };
            for u in units {
                let Value::Ref(uid) = u else { continue };
                let Some(unit) = self.file.instances.get(uid) else {
                    continue;
                };
                if unit.part("PLANE_ANGLE_UNIT").is_none() {
                    continue;
                }
                if let Some(conv) = unit.part("CONVERSION_BASED_UNIT") {
                    if let Some(Value::Ref(m)) = conv.params.get(1) {
                        if let Some(measure) = self.file.instances.get(m) {
                            if let Some(v) = measure.parts[0].params.first().and_then(real_of) {
                                if v > 0.0 {
                                    return v;
                                }
                            }
                        }
                    }
                }
            }
        }
        1.0
    }

    /// The length unit named in the global unit context (for reports; coordinates stay in it).
    pub(crate) fn length_unit(&self) -> String {
        for id in &self.file.order {
            let inst = &self.file.instances[id];
            let Some(ctx) = inst.part("GLOBAL_UNIT_ASSIGNED_CONTEXT") else {
                continue;
            };
            let Some(Value::List(units)) = ctx.params.first() else {
                continue;
            };
            for u in units {
                let Value::Ref(uid) = u else { continue };
                let Some(unit) = self.file.instances.get(uid) else {
                    continue;
                };
                if unit.part("LENGTH_UNIT").is_none() {
                    continue;
                }
                if let Some(si) = unit.part("SI_UNIT") {
                    let word = |v: Option<&Value>| match v {
                        Some(Value::Enum(e)) => e.to_ascii_lowercase(),
                        _ => String::new(),
                    };
                    return format!("{}{}", word(si.params.first()), word(si.params.get(1)));
                }
                if let Some(conv) = unit.part("CONVERSION_BASED_UNIT") {
                    if let Some(Value::Str(s)) = conv.params.first() {
                        return s.to_ascii_lowercase();
                    }
                }
            }
        }
        "unknown".into()
    }

    fn point(&self, from: u64, id: u64) -> Result<[f64; 3], StepError> {
        let p = self.simple(from, id, &["CARTESIAN_POINT"], "as a point")?;
        let c = p.reals(1)?;
        if c.len() != 3 {
            return Err(invalid(id, p.inst, "a 3D point needs three coordinates"));
        }
        Ok([c[0], c[1], c[2]])
    }

    fn point2(&self, from: u64, id: u64) -> Result<[f64; 2], StepError> {
        let p = self.simple(from, id, &["CARTESIAN_POINT"], "as a 2D point")?;
        let c = p.reals(1)?;
        if c.len() != 2 {
            return Err(invalid(id, p.inst, "a 2D point needs two coordinates"));
        }
        Ok([c[0], c[1]])
    }

    fn direction2(&self, from: u64, id: u64) -> Result<[f64; 2], StepError> {
        let p = self.simple(from, id, &["DIRECTION"], "as a 2D direction")?;
        let c = p.reals(1)?;
        let n = if c.len() == 2 { c[0].hypot(c[1]) } else { 0.0 };
        if !(n > 0.0 && n.is_finite()) {
            return Err(invalid(
                id,
                p.inst,
                "a 2D direction needs two components, not both 0",
            ));
        }
        Ok([c[0] / n, c[1] / n])
    }

    /// The 2D curve of a pcurve: `LINE`, `CIRCLE`, `ELLIPSE` (on an `AXIS2_PLACEMENT_2D`) or a
    /// (rational) B-spline, in the file's parameter units.
    fn curve2(&self, from: u64, id: u64) -> Result<Curve2, StepError> {
        let inst = self.inst(from, id)?;
        if inst.parts.len() > 1 {
            return match self.bspline_curve_in(id, inst, 2)? {
                Curve::Pieces(p, _) => Ok(Curve2::Pieces(p)),
                _ => Err(unsupported(id, inst, "as a 2D curve")),
            };
        }
        let p = Params {
            id,
            inst,
            part: &inst.parts[0],
        };
        Ok(match p.part.name.as_str() {
            "LINE" => {
                let o = self.point2(id, p.refid(1)?)?;
                let v = self.simple(id, p.refid(2)?, &["VECTOR"], "as a line direction")?;
                let d = self.direction2(v.id, v.refid(1)?)?;
                let m = v.real(2)?;
                Curve2::Line(o, [d[0] * m, d[1] * m])
            }
            "CIRCLE" | "ELLIPSE" => {
                let pl = self.simple(
                    id,
                    p.refid(1)?,
                    &["AXIS2_PLACEMENT_2D"],
                    "as a 2D placement",
                )?;
                let o = self.point2(pl.id, pl.refid(1)?)?;
                let x = match pl.opt_ref(2)? {
                    Some(r) => self.direction2(pl.id, r)?,
                    None => [1.0, 0.0],
                };
                let a = p.real(2)?;
                let b = if p.part.name == "CIRCLE" {
                    a
                } else {
                    p.real(3)?
                };
                if !(a > 0.0 && b > 0.0) {
                    return Err(invalid(id, inst, "radii must be positive"));
                }
                Curve2::Conic {
                    o,
                    x,
                    y: [-x[1], x[0]],
                    a,
                    b,
                    angle: self.angle_factor,
                }
            }
            "B_SPLINE_CURVE_WITH_KNOTS" => match self.bspline_curve_in(id, inst, 2)? {
                Curve::Pieces(p, _) => Curve2::Pieces(p),
                _ => return Err(unsupported(id, inst, "as a 2D curve")),
            },
            _ => return Err(unsupported(id, inst, "as a 2D curve")),
        })
    }

    /// The pcurves of an edge whose geometry is a `SURFACE_CURVE` / `SEAM_CURVE`, with the
    /// edge's parameter range on its 3D curve `curve` (from start to end vertex). Pcurves this
    /// reader cannot use are counted in `pcurves_unreadable` (their edge uses are mapped from 3D).
    fn read_pcurves(
        &mut self,
        geometry: u64,
        curve: &Curve,
        ends: [[f64; 3]; 2],
        same_sense: bool,
        tol: f64,
    ) -> Result<Vec<EdgePcurve>, StepError> {
        let inst = self.inst(geometry, geometry)?;
        let [part] = inst.parts.as_slice() else {
            return Ok(Vec::new());
        };
        if !matches!(part.name.as_str(), "SURFACE_CURVE" | "SEAM_CURVE") {
            return Ok(Vec::new());
        }
        let p = Params {
            id: geometry,
            inst,
            part,
        };
        let mut out = Vec::new();
        let mut candidates = Vec::new();
        for r in p.refs(2)? {
            let a = self.inst(geometry, r)?;
            // A SURFACE in the list names a surface without a pcurve: nothing to use.
            if let [pp] = a.parts.as_slice() {
                if pp.name == "PCURVE" {
                    let pc = Params {
                        id: r,
                        inst: a,
                        part: pp,
                    };
                    candidates.push((pc.refid(1)?, pc.refid(2)?, r));
                }
            }
        }
        if candidates.is_empty() {
            return Ok(out);
        }
        let range = if same_sense {
            param_range(curve, ends[0], ends[1], self.angle_factor, tol)
        } else {
            param_range(curve, ends[1], ends[0], self.angle_factor, tol).map(|[a, b]| [b, a])
        };
        for (surface, rep, pid) in candidates {
            let Some(range) = range else {
                self.pcurves_unreadable += 1;
                continue;
            };
            let items = match self.simple(
                pid,
                rep,
                &["DEFINITIONAL_REPRESENTATION"],
                "as a pcurve's representation",
            ) {
                Ok(dr) => dr.refs(1).unwrap_or_default(),
                Err(e @ StepError::Dangling { .. }) => return Err(e),
                Err(_) => Vec::new(),
            };
            match items.first().map(|&c| self.curve2(rep, c)) {
                Some(Ok(c)) => out.push(EdgePcurve {
                    surface,
                    curve: c,
                    range,
                }),
                Some(Err(StepError::Dangling { id, target })) => {
                    return Err(StepError::Dangling { id, target });
                }
                _ => self.pcurves_unreadable += 1,
            }
        }
        Ok(out)
    }

    fn direction(&self, from: u64, id: u64) -> Result<[f64; 3], StepError> {
        let p = self.simple(from, id, &["DIRECTION"], "as a direction")?;
        let c = p.reals(1)?;
        if c.len() != 3 {
            return Err(invalid(id, p.inst, "a 3D direction needs three components"));
        }
        unit([c[0], c[1], c[2]]).ok_or_else(|| invalid(id, p.inst, "zero direction"))
    }

    fn placement(&self, from: u64, id: u64) -> Result<Frame, StepError> {
        let p = self.simple(from, id, &["AXIS2_PLACEMENT_3D"], "as a placement")?;
        let o = self.point(id, p.refid(1)?)?;
        let axis = match p.opt_ref(2)? {
            Some(a) => Some(self.direction(id, a)?),
            None => None,
        };
        let refd = match p.opt_ref(3)? {
            Some(a) => Some(self.direction(id, a)?),
            None => None,
        };
        frame(o, axis, refd).map_err(|m| invalid(id, p.inst, m))
    }

    fn vertex(&self, from: u64, id: u64) -> Result<[f64; 3], StepError> {
        let p = self.simple(from, id, &["VERTEX_POINT"], "as a vertex")?;
        self.point(id, p.refid(1)?)
    }

    /// A curve entity (cached).
    pub(crate) fn curve(&mut self, from: u64, id: u64) -> Result<Curve, StepError> {
        if let Some(c) = self.curves.get(&id) {
            return Ok(c.clone());
        }
        let inst = self.inst(from, id)?;
        let c = if inst.parts.len() > 1 {
            self.bspline_curve(id, inst)?
        } else {
            let p = Params {
                id,
                inst,
                part: &inst.parts[0],
            };
            match p.part.name.as_str() {
                "LINE" => {
                    let o = self.point(id, p.refid(1)?)?;
                    let v = self.simple(id, p.refid(2)?, &["VECTOR"], "as a line direction")?;
                    let d = self.direction(v.id, v.refid(1)?)?;
                    let m = v.real(2)?;
                    Curve::Line(o, [d[0] * m, d[1] * m, d[2] * m])
                }
                "CIRCLE" => {
                    let f = self.placement(id, p.refid(1)?)?;
                    let r = p.real(2)?;
                    if r <= 0.0 {
                        return Err(invalid(id, inst, "radius must be positive"));
                    }
                    Curve::Conic(f, r, r)
                }
                "ELLIPSE" => {
                    let f = self.placement(id, p.refid(1)?)?;
                    let (a, b) = (p.real(2)?, p.real(3)?);
                    if a <= 0.0 || b <= 0.0 {
                        return Err(invalid(id, inst, "semi-axes must be positive"));
                    }
                    Curve::Conic(f, a, b)
                }
                "B_SPLINE_CURVE_WITH_KNOTS" => self.bspline_curve(id, inst)?,
                "TRIMMED_CURVE" => {
                    let basis = self.curve(id, p.refid(1)?)?;
                    Curve::Trimmed(Box::new(basis), p.boolean(4)?)
                }
                "SURFACE_CURVE" | "SEAM_CURVE" => self.curve(id, p.refid(1)?)?,
                _ => return Err(unsupported(id, inst, "as a curve")),
            }
        };
        self.curves.insert(id, c.clone());
        Ok(c)
    }

    /// `B_SPLINE_CURVE_WITH_KNOTS` (simple) or the complex form with `RATIONAL_B_SPLINE_CURVE`.
    fn bspline_curve(&self, id: u64, inst: &'a Instance) -> Result<Curve, StepError> {
        self.bspline_curve_in(id, inst, 3)
    }

    /// A B-spline curve with `dim`-dimensional control points (2 for a pcurve's curve; the
    /// third coordinate is then 0).
    fn bspline_curve_in(
        &self,
        id: u64,
        inst: &'a Instance,
        dim: usize,
    ) -> Result<Curve, StepError> {
        let (head, off, knots_part, koff, weights) = if inst.parts.len() == 1 {
            let part = &inst.parts[0];
            (part, 1, part, 6, None)
        } else {
            let head = inst
                .part("B_SPLINE_CURVE")
                .ok_or_else(|| unsupported(id, inst, "as a curve"))?;
            let kp = inst
                .part("B_SPLINE_CURVE_WITH_KNOTS")
                .ok_or_else(|| unsupported(id, inst, "as a curve (no knots)"))?;
            let w = inst.part("RATIONAL_B_SPLINE_CURVE");
            (head, 0, kp, 0, w)
        };
        let h = Params {
            id,
            inst,
            part: head,
        };
        let k = Params {
            id,
            inst,
            part: knots_part,
        };
        let degree = h.int(off)?;
        let ctrl_ids = h.refs(off + 1)?;
        let closed = h.boolean(off + 3).unwrap_or(false);
        let mults = k.ints(koff)?;
        let knots = k.reals(koff + 1)?;
        let ws = match weights {
            Some(w) => Params { id, inst, part: w }.reals(0)?,
            None => vec![1.0; ctrl_ids.len()],
        };
        if ws.len() != ctrl_ids.len() || ws.iter().any(|&w| w <= 0.0) {
            return Err(invalid(
                id,
                inst,
                "weights must be positive, one per control point",
            ));
        }
        let p = usize::try_from(degree).map_err(|_| invalid(id, inst, "negative degree"))?;
        let u =
            expand_knots(&mults, &knots, ctrl_ids.len(), p).map_err(|m| invalid(id, inst, m))?;
        let mut ctrl = Vec::with_capacity(ctrl_ids.len());
        for (&c, &w) in ctrl_ids.iter().zip(&ws) {
            let point = if dim == 2 {
                let [x, y] = self.point2(id, c)?;
                [x, y, 0.0]
            } else {
                self.point(id, c)?
            };
            ctrl.push(vec![hom(point, w)]);
        }
        let pieces: Pieces = extract(p, &u, &ctrl)
            .into_iter()
            .map(|(a, b, rows)| (a, b, rows.into_iter().map(|r| r[0]).collect()))
            .collect();
        if pieces.is_empty() {
            return Err(invalid(id, inst, "empty parameter range"));
        }
        let first = super::nurbs::euc(pieces[0].2[0]);
        let last = super::nurbs::euc(*pieces[pieces.len() - 1].2.last().unwrap_or(&pieces[0].2[0]));
        let closes = closed || norm(sub(first, last)) <= 1e-12 * (1.0 + norm(first));
        Ok(Curve::Pieces(pieces, closes))
    }

    /// Bézier pieces of `c` from point `a` to point `b`, running in the curve's direction.
    fn between(
        &self,
        c: &Curve,
        a: [f64; 3],
        b: [f64; 3],
        tol: f64,
    ) -> Result<Vec<Vec<Homogeneous>>, String> {
        let same = norm(sub(a, b)) <= tol;
        Ok(match c {
            Curve::Line(..) => {
                if same {
                    return Err("a line edge that starts and ends at one vertex".into());
                }
                vec![vec![hom(a, 1.0), hom(b, 1.0)]]
            }
            Curve::Conic(f, ra, rb) => {
                let t0 = conic_angle(f, *ra, *rb, a);
                let t1 = if same {
                    t0 + std::f64::consts::TAU
                } else {
                    next_turn(t0, conic_angle(f, *ra, *rb, b))
                };
                conic_pieces(f, *ra, *rb, t0, t1)
                    .into_iter()
                    .map(|p| p.2)
                    .collect()
            }
            Curve::Pieces(pieces, closed) => {
                let lo = pieces[0].0;
                let hi = pieces[pieces.len() - 1].1;
                let mut ta = invert_curve(pieces, a);
                let mut tb = invert_curve(pieces, b);
                if same && *closed {
                    (ta, tb) = (lo, hi);
                }
                if *closed && tb <= ta {
                    // Runs across the closing point: ta → hi, then lo → tb.
                    let mut out = clip(pieces, ta, hi);
                    out.extend(clip(pieces, lo, tb));
                    return Ok(out);
                }
                if tb <= ta {
                    return Err(format!(
                        "edge vertices at parameters {ta} and {tb} run against the curve"
                    ));
                }
                clip(pieces, ta, tb)
            }
            Curve::Trimmed(basis, sense) => {
                if *sense {
                    self.between(basis, a, b, tol)?
                } else {
                    reverse(self.between(basis, b, a, tol)?)
                }
            }
        })
    }

    /// The geometry of `EDGE_CURVE` `id` from its start to its end vertex (cached).
    pub(crate) fn edge(
        &mut self,
        from: u64,
        id: u64,
        tol: f64,
    ) -> Result<Vec<Vec<Homogeneous>>, StepError> {
        if let Some(e) = self.edges.get(&id) {
            return Ok(e.clone());
        }
        let p = self.simple(from, id, &["EDGE_CURVE"], "as an edge")?;
        let v1 = self.vertex(id, p.refid(1)?)?;
        let v2 = self.vertex(id, p.refid(2)?)?;
        let curve = self.curve(id, p.refid(3)?)?;
        let same_sense = p.boolean(4)?;
        let pieces = if same_sense {
            self.between(&curve, v1, v2, tol)
        } else {
            self.between(&curve, v2, v1, tol).map(reverse)
        }
        .map_err(|m| geometry(id, p.inst, m))?;
        let pcurves = self.read_pcurves(p.refid(3)?, &curve, [v1, v2], same_sense, tol)?;
        if !pcurves.is_empty() {
            self.pcurves.insert(id, pcurves);
        }
        self.edges.insert(id, pieces.clone());
        Ok(pieces)
    }

    /// The surface of a face.
    pub(crate) fn surface(&mut self, from: u64, id: u64, tol: f64) -> Result<Surface, StepError> {
        let inst = self.inst(from, id)?;
        if inst.parts.len() > 1 {
            return self.bspline_surface(id, inst, tol);
        }
        let p = Params {
            id,
            inst,
            part: &inst.parts[0],
        };
        let positive = |v: f64, what: &str| {
            if v > 0.0 {
                Ok(v)
            } else {
                Err(invalid(id, inst, format!("{what} must be positive")))
            }
        };
        Ok(match p.part.name.as_str() {
            "PLANE" => Surface::Plane(self.placement(id, p.refid(1)?)?),
            "CYLINDRICAL_SURFACE" => Surface::Cylinder(
                self.placement(id, p.refid(1)?)?,
                positive(p.real(2)?, "radius")?,
            ),
            "CONICAL_SURFACE" => {
                let angle = p.real(3)? * self.angle_factor;
                if angle.is_nan() || angle.abs() >= std::f64::consts::FRAC_PI_2 {
                    return Err(invalid(id, inst, "semi-angle must be below 90°"));
                }
                Surface::Cone(self.placement(id, p.refid(1)?)?, p.real(2)?, angle.tan())
            }
            "SPHERICAL_SURFACE" => Surface::Sphere(
                self.placement(id, p.refid(1)?)?,
                positive(p.real(2)?, "radius")?,
            ),
            "TOROIDAL_SURFACE" => Surface::Torus(
                self.placement(id, p.refid(1)?)?,
                positive(p.real(2)?, "major radius")?,
                positive(p.real(3)?, "minor radius")?,
            ),
            "B_SPLINE_SURFACE_WITH_KNOTS" => self.bspline_surface(id, inst, tol)?,
            "SURFACE_OF_LINEAR_EXTRUSION" => {
                let pieces = self.swept_pieces(id, p.refid(1)?)?;
                let v = self.simple(id, p.refid(2)?, &["VECTOR"], "as an extrusion axis")?;
                let d = self.direction(v.id, v.refid(1)?)?;
                let m = v.real(2)?;
                if m == 0.0 {
                    return Err(invalid(id, inst, "zero extrusion vector"));
                }
                Surface::Extrusion(pieces, [d[0] * m, d[1] * m, d[2] * m])
            }
            "SURFACE_OF_REVOLUTION" => {
                let pieces = self.swept_pieces(id, p.refid(1)?)?;
                let ax = self.simple(
                    id,
                    p.refid(2)?,
                    &["AXIS1_PLACEMENT"],
                    "as a revolution axis",
                )?;
                let a = self.point(ax.id, ax.refid(1)?)?;
                let d = match ax.opt_ref(2)? {
                    Some(r) => self.direction(ax.id, r)?,
                    None => [0.0, 0.0, 1.0],
                };
                revolution(&pieces, a, d, tol).map_err(|m| geometry(id, inst, m))?
            }
            _ => return Err(unsupported(id, inst, "as a face surface")),
        })
    }

    /// A swept curve over its whole (bounded) parameter range.
    fn swept_pieces(&mut self, from: u64, id: u64) -> Result<Pieces, StepError> {
        match self.curve(from, id)? {
            Curve::Pieces(p, _) => Ok(p),
            Curve::Conic(f, a, b) => Ok(conic_pieces(&f, a, b, 0.0, std::f64::consts::TAU)),
            _ => {
                let inst = self.inst(from, id)?;
                Err(unsupported(
                    id,
                    inst,
                    "as a swept curve (unbounded or trimmed)",
                ))
            }
        }
    }

    fn bspline_surface(&self, id: u64, inst: &'a Instance, tol: f64) -> Result<Surface, StepError> {
        let (head, off, kp, koff, weights) = if inst.parts.len() == 1 {
            let part = &inst.parts[0];
            (part, 1, part, 8, None)
        } else {
            let head = inst
                .part("B_SPLINE_SURFACE")
                .ok_or_else(|| unsupported(id, inst, "as a face surface"))?;
            let kp = inst
                .part("B_SPLINE_SURFACE_WITH_KNOTS")
                .ok_or_else(|| unsupported(id, inst, "as a face surface (no knots)"))?;
            (head, 0, kp, 0, inst.part("RATIONAL_B_SPLINE_SURFACE"))
        };
        let h = Params {
            id,
            inst,
            part: head,
        };
        let k = Params { id, inst, part: kp };
        let pu = usize::try_from(h.int(off)?).map_err(|_| invalid(id, inst, "negative degree"))?;
        let pv =
            usize::try_from(h.int(off + 1)?).map_err(|_| invalid(id, inst, "negative degree"))?;
        let rows = h.list(off + 2)?;
        let mut net: Vec<Vec<u64>> = Vec::with_capacity(rows.len().min(super::nurbs::MAX_CONTROL));
        for r in rows {
            match r {
                Value::List(l) => net.push(
                    l.iter()
                        .map(|v| match v {
                            Value::Ref(x) => Ok(*x),
                            _ => Err(invalid(id, inst, "control points must be references")),
                        })
                        .collect::<Result<_, _>>()?,
                ),
                _ => return Err(invalid(id, inst, "control points must be a list of lists")),
            }
        }
        let nu = net.len();
        let nv = net.first().map_or(0, Vec::len);
        if net.iter().any(|r| r.len() != nv) {
            return Err(invalid(id, inst, "control-point rows of different lengths"));
        }
        let weights: Vec<Vec<f64>> = match weights {
            Some(w) => {
                let wp = Params { id, inst, part: w };
                let l = wp.list(0)?;
                let mut out = Vec::with_capacity(l.len());
                for row in l {
                    match row {
                        Value::List(r) => out.push(
                            r.iter()
                                .map(|v| real_of(v).ok_or_else(|| invalid(id, inst, "bad weight")))
                                .collect::<Result<Vec<f64>, _>>()?,
                        ),
                        _ => return Err(invalid(id, inst, "weights must be a list of lists")),
                    }
                }
                out
            }
            None => vec![vec![1.0; nv]; nu],
        };
        if weights.len() != nu
            || weights
                .iter()
                .any(|r| r.len() != nv || r.iter().any(|&w| w <= 0.0))
        {
            return Err(invalid(
                id,
                inst,
                "weights must be positive, one per control point",
            ));
        }
        let uk = expand_knots(&k.ints(koff)?, &k.reals(koff + 2)?, nu, pu)
            .map_err(|m| invalid(id, inst, format!("u knots: {m}")))?;
        let vk = expand_knots(&k.ints(koff + 1)?, &k.reals(koff + 3)?, nv, pv)
            .map_err(|m| invalid(id, inst, format!("v knots: {m}")))?;
        if nu.saturating_mul(nv) > super::nurbs::MAX_CONTROL {
            return Err(invalid(id, inst, format!("{nu} x {nv} control points")));
        }
        let mut hnet: Vec<Vec<Homogeneous>> = Vec::with_capacity(nu);
        for (r, wr) in net.iter().zip(&weights) {
            let mut row = Vec::with_capacity(nv);
            for (&c, &w) in r.iter().zip(wr) {
                row.push(hom(self.point(id, c)?, w));
            }
            hnet.push(row);
        }
        let mut patches = Vec::new();
        for (u0, u1, urows) in extract(pu, &uk, &hnet) {
            // urows: pu+1 rows of nv points; extract along v for the transposed net.
            let cols: Vec<Vec<Homogeneous>> = (0..nv)
                .map(|j| urows.iter().map(|r| r[j]).collect())
                .collect();
            for (v0, v1, vcols) in extract(pv, &vk, &cols) {
                // vcols: pv+1 entries, each a column of pu+1 points (over u).
                let mut pts = Vec::with_capacity((pu + 1) * (pv + 1));
                let mut ws = Vec::with_capacity((pu + 1) * (pv + 1));
                for i in 0..=pu {
                    for vc in vcols.iter().take(pv + 1) {
                        let hh = vc[i];
                        pts.push(super::nurbs::euc(hh));
                        ws.push(hh[3]);
                    }
                }
                let patch = Patch::rational(pu, pv, pts, ws)
                    .map_err(|e| invalid(id, inst, e.to_string()))?;
                patches.push(UvPatch {
                    patch,
                    u: [u0, u1],
                    v: [v0, v1],
                    map: [ParamMap::Linear, ParamMap::Linear],
                });
            }
        }
        let (period_u, period_v) = detect_periods(&patches, tol);
        Ok(Surface::from_patches(patches, period_u, period_v))
    }

    /// A face: `ADVANCED_FACE` / `FACE_SURFACE`.
    pub(crate) fn face(&mut self, from: u64, id: u64, tol: f64) -> Result<RawFace, StepError> {
        let p = self.simple(from, id, &["ADVANCED_FACE", "FACE_SURFACE"], "as a face")?;
        let surface_id = p.refid(2)?;
        let surface = self.surface(id, surface_id, tol)?;
        let a = self.angle_factor;
        let surface_inst = self.inst(id, surface_id)?;
        let pcurve_units = match surface {
            Surface::Plane(_) => Some([1.0, 1.0]),
            Surface::Cylinder(..) | Surface::Cone(..) => Some([a, 1.0]),
            Surface::Sphere(..) | Surface::Torus(..) => Some([a, a]),
            // B-spline surfaces keep their knot parameters; surfaces of revolution (also
            // patches here) run linearly in the rational arcs' parameter, not in the angle.
            Surface::Patches { .. } => (surface_inst.parts.len() > 1
                || surface_inst.parts[0].name == "B_SPLINE_SURFACE_WITH_KNOTS")
                .then_some([1.0, 1.0]),
            Surface::Extrusion(..) => None,
        };
        let same_sense = p.boolean(3)?;
        let mut loops = Vec::new();
        for b in p.refs(1)? {
            let bp = self.simple(
                id,
                b,
                &["FACE_OUTER_BOUND", "FACE_BOUND"],
                "as a face bound",
            )?;
            let orientation = bp.boolean(2)?;
            let lid = bp.refid(1)?;
            let linst = self.inst(b, lid)?;
            match linst.parts.as_slice() {
                [part] if part.name == "VERTEX_LOOP" => continue,
                [part] if part.name == "EDGE_LOOP" => {
                    let lp = Params {
                        id: lid,
                        inst: linst,
                        part,
                    };
                    let mut uses = Vec::new();
                    for oe in lp.refs(1)? {
                        let op = self.simple(lid, oe, &["ORIENTED_EDGE"], "in an edge loop")?;
                        let edge = op.refid(3)?;
                        let forward = op.boolean(4)? == orientation;
                        self.edge(oe, edge, tol)?;
                        uses.push(EdgeUse { edge, forward });
                    }
                    if !orientation {
                        uses.reverse();
                    }
                    loops.push(uses);
                }
                _ => return Err(unsupported(lid, linst, "as a face loop")),
            }
        }
        Ok(RawFace {
            id,
            surface,
            same_sense,
            surface_id,
            pcurve_units,
            loops,
        })
    }

    /// All faces of the model: those of the solids and surface models if there are any,
    /// else those of every shell, else every face.
    pub(crate) fn faces(&mut self) -> Result<(Vec<RawFace>, Topology), StepError> {
        let mut topo = Topology {
            length_unit: self.length_unit(),
            ..Topology::default()
        };
        let mut shells = Vec::new();
        let mut roots = false;
        for &id in &self.file.order {
            let inst = &self.file.instances[&id];
            let [part] = inst.parts.as_slice() else {
                continue;
            };
            let p = Params { id, inst, part };
            match part.name.as_str() {
                "MANIFOLD_SOLID_BREP" => {
                    roots = true;
                    topo.solids += 1;
                    shells.push((id, p.refid(1)?));
                }
                "BREP_WITH_VOIDS" => {
                    roots = true;
                    topo.solids += 1;
                    shells.push((id, p.refid(1)?));
                    for v in p.refs(2)? {
                        shells.push((id, v));
                    }
                }
                "SHELL_BASED_SURFACE_MODEL" => {
                    roots = true;
                    for s in p.refs(1)? {
                        shells.push((id, s));
                    }
                }
                _ => {}
            }
        }
        if !roots {
            for &id in &self.file.order {
                let inst = &self.file.instances[&id];
                if matches!(inst.parts.as_slice(), [p] if p.name == "CLOSED_SHELL" || p.name == "OPEN_SHELL")
                {
                    shells.push((id, id));
                }
            }
        }
        let mut face_ids = Vec::new();
        let mut seen_shells = HashSet::new();
        for (from, s) in shells {
            if !seen_shells.insert(s) {
                continue;
            }
            let sp = self.simple(
                from,
                s,
                &["CLOSED_SHELL", "OPEN_SHELL", "ORIENTED_CLOSED_SHELL"],
                "as a shell",
            )?;
            if sp.part.name == "ORIENTED_CLOSED_SHELL" {
                return Err(unsupported(s, sp.inst, "(oriented shells)"));
            }
            topo.shells += 1;
            for f in sp.refs(1)? {
                face_ids.push((s, f));
            }
        }
        if face_ids.is_empty() {
            for &id in &self.file.order {
                let inst = &self.file.instances[&id];
                if matches!(inst.parts.as_slice(), [p] if p.name == "ADVANCED_FACE") {
                    face_ids.push((id, id));
                }
            }
        }
        // A model-size tolerance for "same point" tests (closed curves, periodic surfaces).
        let tol = self.model_tolerance();
        let mut seen = HashSet::new();
        let mut faces = Vec::new();
        for (from, f) in face_ids {
            if seen.insert(f) {
                faces.push(self.face(from, f, tol)?);
            }
        }
        if faces.is_empty() {
            return Err(StepError::NoFaces);
        }
        Ok((faces, topo))
    }

    /// `1e-9 ×` the diagonal of all vertex points (vertices bound the model's edges).
    pub(crate) fn model_tolerance(&self) -> f64 {
        let mut lo = [f64::INFINITY; 3];
        let mut hi = [f64::NEG_INFINITY; 3];
        for inst in self.file.instances.values() {
            if let [part] = inst.parts.as_slice() {
                if part.name == "VERTEX_POINT" {
                    if let Some(Value::Ref(r)) = part.params.get(1) {
                        if let Some(pt) = self.file.instances.get(r) {
                            if let Some(Value::List(c)) = pt.parts[0].params.get(1) {
                                for (k, v) in c.iter().take(3).enumerate() {
                                    if let Some(x) = real_of(v) {
                                        lo[k] = lo[k].min(x);
                                        hi[k] = hi[k].max(x);
                                    }
                                }
                            }
                        }
                    }
                }
            }
        }
        let d = norm(sub(hi, lo));
        if d.is_finite() && d > 0.0 {
            1e-9 * d
        } else {
            1e-12
        }
    }
}

/// The parameters of `curve` at the points `a` and `b`, running in the curve's direction from
/// `a` to `b`, in the file's units (angles divided by `angle_factor`, radians per unit): the
/// range a pcurve of this curve shares. `None` where the reader has no such range: trimmed
/// curves, and a closed B-spline run across its closing point.
fn param_range(
    curve: &Curve,
    a: [f64; 3],
    b: [f64; 3],
    angle_factor: f64,
    tol: f64,
) -> Option<[f64; 2]> {
    let same = norm(sub(a, b)) <= tol;
    match curve {
        Curve::Line(o, d) => {
            let dd = dot(*d, *d);
            let t = |p: [f64; 3]| dot(sub(p, *o), *d) / dd;
            (!same).then(|| [t(a), t(b)])
        }
        Curve::Conic(f, ra, rb) => {
            let t0 = conic_angle(f, *ra, *rb, a);
            let t1 = if same {
                t0 + std::f64::consts::TAU
            } else {
                next_turn(t0, conic_angle(f, *ra, *rb, b))
            };
            Some([t0 / angle_factor, t1 / angle_factor])
        }
        Curve::Pieces(pieces, closed) => {
            let (lo, hi) = (pieces[0].0, pieces[pieces.len() - 1].1);
            if same && *closed {
                return Some([lo, hi]);
            }
            let (ta, tb) = (invert_curve(pieces, a), invert_curve(pieces, b));
            (tb > ta).then_some([ta, tb])
        }
        Curve::Trimmed(..) => None,
    }
}

/// Reverses a list of Bézier pieces (order and control points).
pub fn reverse(mut pieces: Vec<Vec<Homogeneous>>) -> Vec<Vec<Homogeneous>> {
    pieces.reverse();
    for p in &mut pieces {
        p.reverse();
    }
    pieces
}

/// The Bézier pieces of a piecewise curve between parameters `a < b`.
fn clip(pieces: &Pieces, a: f64, b: f64) -> Vec<Vec<Homogeneous>> {
    let mut out = Vec::new();
    for (lo, hi, c) in pieces {
        let (s, e) = (a.max(*lo), b.min(*hi));
        if e - s <= 1e-14 * (hi - lo) {
            continue;
        }
        out.push(sub_curve(c, (s - lo) / (hi - lo), (e - lo) / (hi - lo)));
    }
    out
}

/// A surface of revolution as rational Bézier patches: `u` the angle (four quarter turns),
/// `v` the swept curve's parameter.
fn revolution(pieces: &Pieces, a: [f64; 3], d: [f64; 3], tol: f64) -> Result<Surface, String> {
    let mut patches = Vec::new();
    let quarter = std::f64::consts::FRAC_PI_2;
    for k in 0..4 {
        let (u0, u1) = (k as f64 * quarter, (k + 1) as f64 * quarter);
        let arc = super::nurbs::unit_arcs(u0, u1);
        let arc = &arc[0];
        for (t0, t1, c) in pieces {
            let mut pts = Vec::new();
            let mut ws = Vec::new();
            for (cs, wa) in arc {
                for h in c {
                    let q = super::nurbs::euc(*h);
                    let rel = sub(q, a);
                    let ht = dot(rel, d);
                    let r = sub(rel, [d[0] * ht, d[1] * ht, d[2] * ht]);
                    let dr = crate::base::vec3::cross(d, r);
                    let p = [
                        a[0] + ht * d[0] + cs[0] * r[0] + cs[1] * dr[0],
                        a[1] + ht * d[1] + cs[0] * r[1] + cs[1] * dr[1],
                        a[2] + ht * d[2] + cs[0] * r[2] + cs[1] * dr[2],
                    ];
                    pts.push(p);
                    ws.push(wa * h[3]);
                }
            }
            let patch = Patch::rational(2, c.len() - 1, pts, ws).map_err(|e| e.to_string())?;
            // The revolution's u is the patch parameter scaled linearly (the trimming loops are
            // mapped by inverting these same patches, so the two agree).
            patches.push(UvPatch {
                patch,
                u: [u0, u1],
                v: [*t0, *t1],
                map: [ParamMap::Linear, ParamMap::Linear],
            });
        }
    }
    let (_, period_v) = detect_periods(&patches, tol);
    Ok(Surface::from_patches(
        patches,
        Some(std::f64::consts::TAU),
        period_v,
    ))
}
