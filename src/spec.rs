//! [`EvaluatorSpec`]: one description of an evaluator — the method and its options — checked by
//! one set of rules ([`EvaluatorSpec::validate`], [`EvaluatorSpec::check`]) and built for any
//! [`Input`] ([`EvaluatorSpec::build`]). The CLI and the Python package translate their
//! arguments into a spec, so both accept the same options and report the same errors.
//!
//! Options are `Option`s: `None` takes the default, `Some` is an explicit choice, and an explicit
//! option the chosen method or input does not use is an error ([`SpecError::OptionForMethod`],
//! [`SpecError::OptionForInput`]), never ignored. Method names, ray directions and grid
//! precisions parse from the strings both front ends accept ([`FromStr`]).
//!
//! ```
//! use gwn::input::Input;
//! use gwn::mesh::Mesh;
//! use gwn::spec::{EvaluatorSpec, Method, SpecError};
//! use gwn::RayAxis;
//! let tet = Input::Mesh(Mesh::from_slices(
//!     &[[0., 0., 0.], [1., 0., 0.], [0., 1., 0.], [0., 0., 1.]],
//!     &[[0, 2, 1], [0, 1, 3], [1, 2, 3], [2, 0, 3]],
//! )?);
//! let spec = EvaluatorSpec { ray: Some("-x".parse::<RayAxis>()?), ..Default::default() };
//! let w = spec.build(&tet)?;
//! assert_eq!((w.name(), w.eval([0.1, 0.1, 0.1])), ("exact", 1.0));
//!
//! let fast = EvaluatorSpec { method: Some("fast".parse::<Method>()?), beta: Some(3.0),
//!     ..Default::default() };
//! assert!((fast.build(&tet)?.eval([0.1, 0.1, 0.1]) - 1.0).abs() < 1e-9);
//!
//! // A NaN or negative tolerance is refused, and so is an option the method does not use.
//! let bad = EvaluatorSpec { tolerance: Some(f64::NAN), ..Default::default() };
//! assert_eq!(bad.validate(), Err(SpecError::Tolerance(f64::NAN.to_string())));
//! let bad = EvaluatorSpec { beta: Some(2.0), ..Default::default() };
//! assert_eq!(bad.build(&tet).err().unwrap().to_string(),
//!            "beta does not apply to the exact method (it is an option of the fast method)");
//! # Ok::<(), Box<dyn std::error::Error>>(())
//! ```

use std::fmt;
use std::str::FromStr;

use crate::eval::Evaluator;
use crate::eval::antipodal::{BoundaryBy, BuildError, DEFAULT_TOLERANCE, Options, WindingNumber};
use crate::eval::direct::DirectWindingNumber;
use crate::eval::fast::{Admissibility, FastParams, FastWindingNumber, PointCloudWindingNumber};
use crate::eval::parity::CrossingParity;
use crate::input::{Input, InputKind};
use crate::kernel::frame::RayAxis;
use crate::kernel::quantize::Precision;
use crate::mesh::Mesh;
#[cfg(feature = "patch")]
use crate::patch::{PatchWindingNumber, surface_quadrature::SurfaceQuadrature};

/// An evaluation method.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Method {
    /// The exact method: the Antipodal evaluator on meshes, the boundary method on patch sets
    /// and STEP models. The default, except for point clouds.
    Exact,
    /// The direct sum (meshes: solid angles of all triangles; patch sets: the surface integral).
    Direct,
    /// Barnes–Hut (meshes and point clouds; the default for point clouds), options `beta` and
    /// `order`.
    Fast,
    /// Closed meshes of any orientation: 1 where a ray crosses the surface an odd number of
    /// times, else 0 ([`CrossingParity`]; the even-odd rule, exact). Options `ray`, `precision`.
    Parity,
}

impl Method {
    /// Every method, in the order of the messages.
    pub const ALL: [Method; 4] = [Method::Exact, Method::Direct, Method::Fast, Method::Parity];

    /// The name [`FromStr`] accepts: `"exact"`, `"direct"`, `"fast"`, `"parity"`.
    pub fn name(self) -> &'static str {
        match self {
            Method::Exact => "exact",
            Method::Direct => "direct",
            Method::Fast => "fast",
            Method::Parity => "parity",
        }
    }

    /// The methods that evaluate `input`.
    pub fn for_input(input: InputKind) -> &'static [Method] {
        match input {
            InputKind::Mesh => &Method::ALL,
            InputKind::Cloud => &[Method::Fast],
            InputKind::Patches => &[Method::Exact, Method::Direct],
            InputKind::Step => &[Method::Exact],
        }
    }
}

impl fmt::Display for Method {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}

/// An option of an [`EvaluatorSpec`], for messages.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum SpecOption {
    /// [`EvaluatorSpec::method`].
    Method,
    /// [`EvaluatorSpec::ray`].
    Ray,
    /// [`EvaluatorSpec::precision`].
    Precision,
    /// [`EvaluatorSpec::tolerance`].
    Tolerance,
    /// [`EvaluatorSpec::beta`].
    Beta,
    /// [`EvaluatorSpec::order`].
    Order,
    /// [`EvaluatorSpec::rule`].
    Rule,
}

impl SpecOption {
    /// The option's name in both front ends (`--ray` / `ray=`).
    pub fn name(self) -> &'static str {
        match self {
            SpecOption::Method => "method",
            SpecOption::Ray => "ray",
            SpecOption::Precision => "precision",
            SpecOption::Tolerance => "tolerance",
            SpecOption::Beta => "beta",
            SpecOption::Order => "order",
            SpecOption::Rule => "rule",
        }
    }

    /// What the option accepts, completing "`name` must be ...".
    fn expected(self) -> &'static str {
        match self {
            SpecOption::Method => "\"exact\", \"direct\", \"fast\" or \"parity\"",
            SpecOption::Ray => "one of +x -x +y -y +z -z",
            SpecOption::Precision => "30 or 60",
            SpecOption::Tolerance => "a finite number >= 0",
            SpecOption::Beta => "a positive finite number",
            SpecOption::Order => "0, 1 or 2",
            SpecOption::Rule => {
                "\"radius\", \"box-diagonal\", \"box-corner\" or \"radius-or-box-corner\""
            }
        }
    }

    /// Which methods use the option, completing "it is an option of ...".
    fn owner(self) -> &'static str {
        match self {
            SpecOption::Ray | SpecOption::Precision => "the exact and parity methods",
            SpecOption::Tolerance => "the exact method, and of the direct method on patch sets",
            SpecOption::Beta | SpecOption::Order | SpecOption::Rule => "the fast method",
            SpecOption::Method => "every method",
        }
    }
}

impl fmt::Display for SpecOption {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}

/// A method name, ray direction or precision that does not parse.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct ParseError {
    /// Which option.
    pub option: SpecOption,
    /// What was given, as written in the message (strings quoted).
    pub given: String,
}

impl fmt::Display for ParseError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(
            f,
            "{} must be {}, got {}",
            self.option,
            self.option.expected(),
            self.given
        )
    }
}

impl std::error::Error for ParseError {}

impl FromStr for Method {
    type Err = ParseError;
    /// `"exact"`, `"direct"`, `"fast"` or `"parity"`.
    fn from_str(s: &str) -> Result<Self, ParseError> {
        Method::ALL
            .into_iter()
            .find(|m| m.name() == s)
            .ok_or_else(|| ParseError {
                option: SpecOption::Method,
                given: format!("{s:?}"),
            })
    }
}

impl FromStr for Admissibility {
    type Err = ParseError;
    /// [`Admissibility::name`]: `"radius"`, `"box-diagonal"`, `"box-corner"`,
    /// `"radius-or-box-corner"`.
    ///
    /// ```
    /// use gwn::eval::fast::Admissibility;
    /// assert_eq!("box-corner".parse(), Ok(Admissibility::BoxCorner));
    /// assert!("corner".parse::<Admissibility>().is_err());
    /// ```
    fn from_str(s: &str) -> Result<Self, ParseError> {
        Admissibility::ALL
            .into_iter()
            .find(|a| a.name() == s)
            .ok_or_else(|| ParseError {
                option: SpecOption::Rule,
                given: format!("{s:?}"),
            })
    }
}

/// The names of the ray directions: `"+z"`, `"-z"`, `"+x"`, ... (`"x"` for `"+x"` too).
fn ray_name(ray: RayAxis) -> &'static str {
    match ray {
        RayAxis::PosZ => "+z",
        RayAxis::NegZ => "-z",
        RayAxis::PosX => "+x",
        RayAxis::NegX => "-x",
        RayAxis::PosY => "+y",
        RayAxis::NegY => "-y",
    }
}

impl fmt::Display for RayAxis {
    /// `+z`, `-x`, ...: the name [`FromStr`] accepts.
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(ray_name(*self))
    }
}

impl FromStr for RayAxis {
    type Err = ParseError;
    /// `"+x"`, `"-x"`, `"+y"`, `"-y"`, `"+z"`, `"-z"`; `"x"`, `"y"`, `"z"` are the positive ones.
    fn from_str(s: &str) -> Result<Self, ParseError> {
        let positive = match s {
            "x" => "+x",
            "y" => "+y",
            "z" => "+z",
            s => s,
        };
        RayAxis::ALL
            .into_iter()
            .find(|&r| ray_name(r) == positive)
            .ok_or_else(|| ParseError {
                option: SpecOption::Ray,
                given: format!("{s:?}"),
            })
    }
}

impl TryFrom<u32> for Precision {
    type Error = ParseError;
    /// 30 or 60 (bits).
    fn try_from(bits: u32) -> Result<Self, ParseError> {
        match bits {
            30 => Ok(Precision::Bits30),
            60 => Ok(Precision::Bits60),
            _ => Err(ParseError {
                option: SpecOption::Precision,
                given: bits.to_string(),
            }),
        }
    }
}

impl FromStr for Precision {
    type Err = ParseError;
    /// `"30"` or `"60"` (bits).
    fn from_str(s: &str) -> Result<Self, ParseError> {
        match s {
            "30" => Ok(Precision::Bits30),
            "60" => Ok(Precision::Bits60),
            _ => Err(ParseError {
                option: SpecOption::Precision,
                given: format!("{s:?}"),
            }),
        }
    }
}

/// Why a spec cannot be built. Displays as one line; the CLI and the Python package show it as
/// it is.
#[derive(Clone, Debug, PartialEq)]
#[non_exhaustive]
pub enum SpecError {
    /// An option value that does not parse.
    Parse(ParseError),
    /// A tolerance that is NaN, infinite or negative (the value as written).
    Tolerance(String),
    /// A tolerance of 0 for an input whose quadrature needs a positive one.
    ZeroTolerance(InputKind),
    /// A `beta` that is NaN, infinite, zero or negative (the value as written).
    Beta(String),
    /// An expansion order above 2.
    Order(u8),
    /// An option given for a method that does not use it.
    OptionForMethod {
        /// The option.
        option: SpecOption,
        /// The method chosen (or the input's default).
        method: Method,
    },
    /// An option given for an input whose evaluator (of this method) does not use it.
    OptionForInput {
        /// The option.
        option: SpecOption,
        /// The method chosen (or the input's default).
        method: Method,
        /// The input.
        input: InputKind,
    },
    /// A method that does not evaluate the input.
    MethodForInput {
        /// The method.
        method: Method,
        /// The input.
        input: InputKind,
    },
    /// The exact evaluator could not be built.
    Build(BuildError),
}

impl fmt::Display for SpecError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            SpecError::Parse(e) => e.fmt(f),
            SpecError::Tolerance(t) => {
                let o = SpecOption::Tolerance;
                write!(f, "{o} must be {}, got {t}", o.expected())
            }
            SpecError::ZeroTolerance(input) => write!(
                f,
                "tolerance must be positive for {input} (its quadrature needs a target), got 0"
            ),
            SpecError::Beta(b) => {
                let o = SpecOption::Beta;
                write!(f, "{o} must be {}, got {b}", o.expected())
            }
            SpecError::Order(n) => {
                let o = SpecOption::Order;
                write!(f, "{o} must be {}, got {n}", o.expected())
            }
            SpecError::OptionForMethod { option, method } => write!(
                f,
                "{option} does not apply to the {method} method (it is an option of {})",
                option.owner()
            ),
            SpecError::OptionForInput {
                option,
                method,
                input,
            } => {
                write!(
                    f,
                    "{option} does not apply to the {method} method on {input}"
                )?;
                if *option == SpecOption::Ray && *input == InputKind::Step {
                    f.write_str(" (its evaluator chooses a ray per query)")?;
                }
                Ok(())
            }
            SpecError::MethodForInput { method, input } => {
                let usable: Vec<&str> =
                    Method::for_input(*input).iter().map(|m| m.name()).collect();
                write!(
                    f,
                    "the {method} method does not apply to {input} (use {})",
                    usable.join(" or ")
                )
            }
            SpecError::Build(e) => e.fmt(f),
        }
    }
}

impl std::error::Error for SpecError {}

impl From<ParseError> for SpecError {
    fn from(e: ParseError) -> Self {
        SpecError::Parse(e)
    }
}

#[cfg(feature = "patch")]
impl SpecError {
    /// The spec's error for a tolerance a curved-surface evaluator refuses (which
    /// [`EvaluatorSpec::check`] refuses first: the evaluators check again on their own).
    pub fn refused_tolerance(e: crate::patch::ToleranceError, input: InputKind) -> SpecError {
        if e.0 == 0.0 {
            SpecError::ZeroTolerance(input)
        } else {
            SpecError::Tolerance(e.0.to_string())
        }
    }
}

impl From<BuildError> for SpecError {
    fn from(e: BuildError) -> Self {
        SpecError::Build(e)
    }
}

/// How to evaluate: the method and its options. `Default` is the exact method with its defaults
/// (the fast method for point clouds).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct EvaluatorSpec {
    /// The method (default: [`Method::Exact`], [`Method::Fast`] for point clouds).
    pub method: Option<Method>,
    /// Exact method: the ray direction (default `+z`; meshes and patch sets).
    pub ray: Option<RayAxis>,
    /// Exact method on meshes: the grid precision (default 60 bits).
    pub precision: Option<Precision>,
    /// Target absolute error of `w` (default [`DEFAULT_TOLERANCE`]): the exact method's far
    /// boundary on meshes (`0` is the flat exact loop), the quadratures of patch sets (exact
    /// and direct) and STEP models (positive). A finite number `>= 0`.
    pub tolerance: Option<f64>,
    /// Fast method: Barill's accuracy parameter β, a positive finite number (default 2).
    pub beta: Option<f64>,
    /// Fast method: the expansion order 0, 1 or 2 (default 2).
    pub order: Option<u8>,
    /// Fast method: which node size β multiplies (default [`Admissibility::Radius`], Barill's).
    pub rule: Option<Admissibility>,
    /// Exact method on meshes: how boundary edges are matched (by position unless the front
    /// end keeps the file's vertices as they are); values do not depend on it.
    pub boundary: BoundaryBy,
}

impl EvaluatorSpec {
    /// Checks what does not depend on the input: option values (a NaN or negative tolerance or
    /// `beta`, an order above 2) and options the chosen method does not use. Front ends call it
    /// before loading anything, so bad options fail fast.
    pub fn validate(&self) -> Result<(), SpecError> {
        if let Some(t) = self.tolerance {
            if !(t.is_finite() && t >= 0.0) {
                return Err(SpecError::Tolerance(t.to_string()));
            }
        }
        if let Some(b) = self.beta {
            if !(b.is_finite() && b > 0.0) {
                return Err(SpecError::Beta(b.to_string()));
            }
        }
        if let Some(n) = self.order {
            if n > 2 {
                return Err(SpecError::Order(n));
            }
        }
        if let Some(method) = self.method {
            self.check_method_options(method)?;
        }
        Ok(())
    }

    /// The options given (as [`SpecOption`]s).
    fn given(&self) -> impl Iterator<Item = SpecOption> {
        [
            (self.ray.is_some(), SpecOption::Ray),
            (self.precision.is_some(), SpecOption::Precision),
            (self.tolerance.is_some(), SpecOption::Tolerance),
            (self.beta.is_some(), SpecOption::Beta),
            (self.order.is_some(), SpecOption::Order),
            (self.rule.is_some(), SpecOption::Rule),
        ]
        .into_iter()
        .filter_map(|(given, o)| given.then_some(o))
    }

    /// Options given for `method` that it does not use (on any input).
    fn check_method_options(&self, method: Method) -> Result<(), SpecError> {
        for option in self.given() {
            let used = match option {
                SpecOption::Ray | SpecOption::Precision => {
                    matches!(method, Method::Exact | Method::Parity)
                }
                SpecOption::Tolerance => matches!(method, Method::Exact | Method::Direct),
                SpecOption::Beta | SpecOption::Order | SpecOption::Rule => method == Method::Fast,
                SpecOption::Method => true,
            };
            if !used {
                return Err(SpecError::OptionForMethod { option, method });
            }
        }
        Ok(())
    }

    /// The method for `input`: the one chosen, else exact ([`Method::Fast`] for point clouds).
    pub fn method_for(&self, input: InputKind) -> Method {
        self.method.unwrap_or(match input {
            InputKind::Cloud => Method::Fast,
            _ => Method::Exact,
        })
    }

    /// Every rule for `input`: [`EvaluatorSpec::validate`], the method evaluates the input, and
    /// every option given is used by the method on this input. Returns the method.
    pub fn check(&self, input: InputKind) -> Result<Method, SpecError> {
        self.validate()?;
        let method = self.method_for(input);
        if !Method::for_input(input).contains(&method) {
            return Err(SpecError::MethodForInput { method, input });
        }
        self.check_method_options(method)?;
        for option in self.given() {
            let used = match (option, input) {
                (SpecOption::Tolerance, InputKind::Mesh) => method == Method::Exact,
                (SpecOption::Precision, i) => i == InputKind::Mesh,
                (SpecOption::Ray, i) => i != InputKind::Step,
                _ => true,
            };
            if !used {
                return Err(SpecError::OptionForInput {
                    option,
                    method,
                    input,
                });
            }
        }
        let curved = matches!(input, InputKind::Patches | InputKind::Step);
        if curved && self.tolerance == Some(0.0) {
            return Err(SpecError::ZeroTolerance(input));
        }
        Ok(method)
    }

    /// The exact mesh evaluator's options (defaults for what is not given).
    pub fn exact_options(&self) -> Options {
        Options {
            precision: self.precision.unwrap_or_default(),
            ray: self.ray.unwrap_or_default(),
            boundary: self.boundary,
            tolerance: self.tolerance.unwrap_or(DEFAULT_TOLERANCE),
        }
    }

    /// The fast method's parameters (defaults for what is not given: β = 2, order 2, Barill's
    /// radius rule).
    pub fn fast_params(&self) -> FastParams {
        let default = FastParams::default();
        FastParams {
            beta: self.beta.unwrap_or(default.beta),
            order: self.order.unwrap_or(default.order),
            admissibility: self.rule.unwrap_or(default.admissibility),
        }
    }

    /// The patch evaluator's options.
    #[cfg(feature = "patch")]
    pub fn patch_options(&self) -> crate::patch::Options {
        crate::patch::Options {
            ray: self.ray.unwrap_or_default(),
            tolerance: self.tolerance.unwrap_or(DEFAULT_TOLERANCE),
        }
    }

    /// The STEP evaluator's options.
    #[cfg(all(feature = "patch", feature = "io"))]
    pub fn step_options(&self) -> crate::patch::step::StepOptions {
        crate::patch::step::StepOptions {
            tolerance: self.tolerance.unwrap_or(DEFAULT_TOLERANCE),
        }
    }

    /// Checks the spec for `input` ([`EvaluatorSpec::check`]) and builds its evaluator.
    pub fn build<'a>(&self, input: &'a Input) -> Result<Box<dyn Evaluator + 'a>, SpecError> {
        let method = self.check(input.kind())?;
        Ok(match (input, method) {
            (Input::Mesh(mesh), _) => self.build_mesh_checked(mesh, method)?,
            (Input::Cloud(cloud), _) => Box::new(PointCloudWindingNumber::with_params(
                cloud,
                self.fast_params(),
            )),
            #[cfg(feature = "patch")]
            (Input::Patches(set), Method::Exact) => Box::new(
                PatchWindingNumber::with_options(set, self.patch_options())
                    .map_err(|e| SpecError::refused_tolerance(e, InputKind::Patches))?,
            ),
            #[cfg(feature = "patch")]
            (Input::Patches(set), _) => Box::new(SurfaceQuadrature::new(
                set,
                self.tolerance.unwrap_or(DEFAULT_TOLERANCE),
            )),
            #[cfg(all(feature = "patch", feature = "io"))]
            (Input::Step(model), _) => Box::new(
                crate::patch::step::StepWindingNumber::with_options(model, self.step_options())
                    .map_err(|e| SpecError::refused_tolerance(e, InputKind::Step))?,
            ),
        })
    }

    /// [`EvaluatorSpec::build`] for a triangle mesh that is not in an [`Input`].
    pub fn build_mesh<'a>(&self, mesh: &'a Mesh) -> Result<Box<dyn Evaluator + 'a>, SpecError> {
        let method = self.check(InputKind::Mesh)?;
        self.build_mesh_checked(mesh, method)
    }

    fn build_mesh_checked<'a>(
        &self,
        mesh: &'a Mesh,
        method: Method,
    ) -> Result<Box<dyn Evaluator + 'a>, SpecError> {
        Ok(match method {
            Method::Exact => Box::new(WindingNumber::with_options(mesh, self.exact_options())?),
            Method::Direct => Box::new(DirectWindingNumber::new(mesh)),
            Method::Fast => Box::new(FastWindingNumber::with_params(mesh, self.fast_params())),
            Method::Parity => Box::new(CrossingParity::with_options(mesh, self.exact_options())?),
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn spec() -> EvaluatorSpec {
        EvaluatorSpec::default()
    }

    #[test]
    fn parsing_round_trips_and_rejects() {
        for m in Method::ALL {
            assert_eq!(m.name().parse::<Method>(), Ok(m));
        }
        for r in RayAxis::ALL {
            assert_eq!(r.to_string().parse::<RayAxis>(), Ok(r));
        }
        assert_eq!("x".parse::<RayAxis>(), Ok(RayAxis::PosX));
        assert_eq!("30".parse::<Precision>(), Ok(Precision::Bits30));
        assert_eq!(Precision::try_from(60), Ok(Precision::Bits60));
        assert_eq!(
            "approx".parse::<Method>().unwrap_err().to_string(),
            "method must be \"exact\", \"direct\", \"fast\" or \"parity\", got \"approx\""
        );
        assert_eq!(
            "+w".parse::<RayAxis>().unwrap_err().to_string(),
            "ray must be one of +x -x +y -y +z -z, got \"+w\""
        );
        assert_eq!(
            Precision::try_from(32).unwrap_err().to_string(),
            "precision must be 30 or 60, got 32"
        );
        assert!("Exact".parse::<Method>().is_err());
        assert!("".parse::<RayAxis>().is_err());
        for a in Admissibility::ALL {
            assert_eq!(a.to_string().parse::<Admissibility>(), Ok(a));
        }
        assert_eq!(
            "corner".parse::<Admissibility>().unwrap_err().to_string(),
            "rule must be \"radius\", \"box-diagonal\", \"box-corner\" or \
             \"radius-or-box-corner\", got \"corner\""
        );
    }

    #[test]
    fn bad_values_are_refused() {
        for t in [f64::NAN, -1e-12, f64::INFINITY, f64::NEG_INFINITY] {
            let s = EvaluatorSpec {
                tolerance: Some(t),
                ..spec()
            };
            assert_eq!(s.validate(), Err(SpecError::Tolerance(t.to_string())));
        }
        for b in [f64::NAN, 0.0, -2.0, f64::INFINITY] {
            let s = EvaluatorSpec {
                method: Some(Method::Fast),
                beta: Some(b),
                ..spec()
            };
            assert_eq!(s.validate(), Err(SpecError::Beta(b.to_string())));
        }
        let s = EvaluatorSpec {
            order: Some(3),
            ..spec()
        };
        assert_eq!(s.validate(), Err(SpecError::Order(3)));
        let ok = EvaluatorSpec {
            tolerance: Some(0.0),
            ..spec()
        };
        assert_eq!(ok.check(InputKind::Mesh), Ok(Method::Exact));
    }

    #[test]
    fn options_must_apply() {
        let exact_beta = EvaluatorSpec {
            method: Some(Method::Exact),
            beta: Some(2.0),
            ..spec()
        };
        assert_eq!(
            exact_beta.validate(),
            Err(SpecError::OptionForMethod {
                option: SpecOption::Beta,
                method: Method::Exact
            })
        );
        // Without a method, beta is fine until the input's default method is known.
        let beta = EvaluatorSpec {
            beta: Some(2.0),
            ..spec()
        };
        assert_eq!(beta.validate(), Ok(()));
        assert_eq!(beta.check(InputKind::Cloud), Ok(Method::Fast));
        assert!(matches!(
            beta.check(InputKind::Mesh),
            Err(SpecError::OptionForMethod { .. })
        ));
        let fast_tol = EvaluatorSpec {
            method: Some(Method::Fast),
            tolerance: Some(1e-3),
            ..spec()
        };
        assert!(fast_tol.validate().is_err());
        let direct_tol = EvaluatorSpec {
            method: Some(Method::Direct),
            tolerance: Some(1e-3),
            ..spec()
        };
        assert_eq!(direct_tol.check(InputKind::Patches), Ok(Method::Direct));
        assert_eq!(
            direct_tol.check(InputKind::Mesh),
            Err(SpecError::OptionForInput {
                option: SpecOption::Tolerance,
                method: Method::Direct,
                input: InputKind::Mesh
            })
        );
        let ray = EvaluatorSpec {
            ray: Some(RayAxis::NegX),
            ..spec()
        };
        assert_eq!(ray.check(InputKind::Patches), Ok(Method::Exact));
        assert_eq!(
            ray.check(InputKind::Step).unwrap_err().to_string(),
            "ray does not apply to the exact method on a STEP model (its evaluator chooses a ray \
             per query)"
        );
        let precision = EvaluatorSpec {
            precision: Some(Precision::Bits30),
            ..spec()
        };
        assert!(precision.check(InputKind::Patches).is_err());
        let zero = EvaluatorSpec {
            tolerance: Some(0.0),
            ..spec()
        };
        assert_eq!(
            zero.check(InputKind::Patches),
            Err(SpecError::ZeroTolerance(InputKind::Patches))
        );
        let direct = EvaluatorSpec {
            method: Some(Method::Direct),
            ..spec()
        };
        assert_eq!(
            direct.check(InputKind::Cloud).unwrap_err().to_string(),
            "the direct method does not apply to a point cloud (use fast)"
        );
        assert_eq!(
            direct.check(InputKind::Step).unwrap_err().to_string(),
            "the direct method does not apply to a STEP model (use exact)"
        );
    }

    fn tet() -> Mesh {
        Mesh::from_slices(
            &[[0., 0., 0.], [1., 0., 0.], [0., 1., 0.], [0., 0., 1.]],
            &[[0, 2, 1], [0, 1, 3], [1, 2, 3], [2, 0, 3]],
        )
        .unwrap()
    }

    #[test]
    fn the_exact_evaluator_refuses_a_bad_tolerance_itself() {
        // Not only through the spec: the constructor no longer reads NaN or -1 as 0.
        for t in [f64::NAN, -1.0, f64::INFINITY] {
            let options = Options {
                tolerance: t,
                ..Options::default()
            };
            assert_eq!(
                WindingNumber::with_options(&tet(), options).err(),
                Some(BuildError::Tolerance(t.to_string()))
            );
        }
        let s = EvaluatorSpec {
            tolerance: Some(-0.5),
            ..spec()
        };
        assert_eq!(
            s.build_mesh(&tet()).err().unwrap().to_string(),
            "tolerance must be a finite number >= 0, got -0.5"
        );
    }

    #[test]
    fn every_input_builds_its_evaluator() {
        let q = [0.1, 0.1, 0.1];
        let input = Input::Mesh(tet());
        for (method, name) in [
            (Method::Exact, "exact"),
            (Method::Direct, "direct"),
            (Method::Fast, "fast"),
        ] {
            let s = EvaluatorSpec {
                method: Some(method),
                ..spec()
            };
            let w = s.build(&input).unwrap();
            assert_eq!(w.name(), name);
            assert!((w.eval(q) - 1.0).abs() < 1e-9, "{name}");
        }
        let cloud = Input::Cloud(
            crate::mesh::PointCloud::new(
                vec![[0.0, 0.0, 0.0], [1.0, 0.0, 0.0]],
                vec![[0.0, 0.0, 1.0], [0.0, 0.0, 1.0]],
                None,
            )
            .unwrap(),
        );
        assert_eq!(spec().build(&cloud).unwrap().name(), "fast point-cloud");
    }

    #[cfg(feature = "patch")]
    #[test]
    fn patch_sets_build_the_exact_and_direct_evaluators() {
        use crate::patch::PatchSet;
        let flat = crate::patch::Patch::polynomial(
            1,
            1,
            vec![[0., 0., 0.], [0., 1., 0.], [1., 0., 0.], [1., 1., 0.]],
        )
        .unwrap();
        let patches = Input::Patches(PatchSet::new(vec![flat]).unwrap());
        assert_eq!(spec().build(&patches).unwrap().name(), "exact (patches)");
        let direct = EvaluatorSpec {
            method: Some(Method::Direct),
            tolerance: Some(1e-6),
            ..spec()
        };
        let (a, b) = (
            spec().build(&patches).unwrap().eval([0.3, 0.4, 0.5]),
            direct.build(&patches).unwrap().eval([0.3, 0.4, 0.5]),
        );
        assert!((a - b).abs() < 1e-5, "{a} vs {b}");
    }

    #[test]
    fn options_reach_the_evaluators() {
        let s = EvaluatorSpec {
            ray: Some(RayAxis::NegY),
            precision: Some(Precision::Bits30),
            tolerance: Some(1e-4),
            boundary: BoundaryBy::Index,
            ..spec()
        };
        assert_eq!(
            s.exact_options(),
            Options {
                precision: Precision::Bits30,
                ray: RayAxis::NegY,
                boundary: BoundaryBy::Index,
                tolerance: 1e-4,
            }
        );
        #[cfg(feature = "patch")]
        assert_eq!(
            s.patch_options(),
            crate::patch::Options {
                ray: RayAxis::NegY,
                tolerance: 1e-4
            }
        );
        assert_eq!(spec().exact_options(), Options::default());
        assert_eq!(spec().fast_params(), FastParams::default());
        let f = EvaluatorSpec {
            beta: Some(3.5),
            order: Some(1),
            ..spec()
        };
        assert_eq!(f.fast_params(), FastParams::barill(3.5, 1));
        let r = EvaluatorSpec {
            rule: Some(Admissibility::RadiusOrBoxCorner),
            ..f
        };
        assert_eq!(
            r.fast_params().admissibility,
            Admissibility::RadiusOrBoxCorner
        );
        let exact_rule = EvaluatorSpec {
            method: Some(Method::Exact),
            rule: Some(Admissibility::BoxCorner),
            ..spec()
        };
        assert_eq!(
            exact_rule.validate(),
            Err(SpecError::OptionForMethod {
                option: SpecOption::Rule,
                method: Method::Exact
            })
        );
    }
}
