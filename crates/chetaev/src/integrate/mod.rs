//! Integration: the methods, and the driver that owns step control, output, events and projection.
//!
//! A method ([`Dopri5`], [`Dop853`], [`Tsit5`], [`Rk4`], [`Rodas4`], [`Rodas5P`]) is a small value holding only
//! its own options, and a recipe: its facts in one place ([`MethodInfo`]: orders, stability size,
//! whether it needs a Jacobian, its step-size [`Controller`], the advice when it fails) and a
//! [`Stepper`] that takes one trial step on an [`OdeSystem`], estimates its error and interpolates
//! inside the last accepted step. It never sees the physics; the driver ([`solve`](crate::solve))
//! never sees a tableau. `docs/adding-a-method.md` shows how a method is added; every method runs
//! the same conformance suite.

pub mod dop853;
pub mod dopri5;
pub mod driver;
pub mod events;
pub mod options;
pub mod projection;
pub mod rk4;
pub mod rodas4;
pub mod rodas5p;
pub mod rosenbrock;
pub mod stiffness;
pub mod system;
pub mod tsit5;

#[cfg(test)]
mod conformance;
#[cfg(test)]
mod testing;

pub use dop853::Dop853;
pub use dopri5::Dopri5;
pub use rk4::Rk4;
pub use rodas4::Rodas4;
pub use rodas5p::Rodas5P;
pub use stiffness::StiffnessDetection;
pub use tsit5::Tsit5;

use crate::error::Error;
use system::OdeSystem;

/// The facts of a method, declared in one place beside its tableau. The driver reads them (the
/// initial step uses `order`, step control uses `control_order` and `controller`), the advice on
/// failure reads them, and the conformance suite checks them.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct MethodInfo {
    /// The name, as in the literature.
    pub name: &'static str,
    /// The order `p` of the step.
    pub order: u32,
    /// The order of the embedded solution of the error estimate (`None` for a fixed-step method).
    pub embedded_order: Option<u32>,
    /// The exponent `q` of step-size control, `h_new ∝ err^(−1/q)`: the lower order of the pair
    /// plus one for most embedded pairs, the order itself for DOP853's combined estimate.
    pub control_order: u32,
    /// The order of the dense output (the local error of the interpolant is `O(h^(dense_order+1))`).
    pub dense_order: u32,
    /// Where the stability region meets the negative real axis, `|hλ|` (`f64::INFINITY` for an
    /// A-stable method); the stiffness test of explicit methods compares against it.
    pub stability_size: f64,
    /// Whether the method evaluates the Jacobian of the right-hand side (implicit methods).
    pub needs_jacobian: bool,
    /// The fixed step size of a method without error control.
    pub fixed_step: Option<f64>,
    /// The step-size controller the method calls for.
    pub controller: Controller,
    /// What to try when this method fails on a problem (shown with the error).
    pub advice: &'static str,
}

/// The facts a method declares, from the literature, with what follows from them filled in: a
/// method is declared in one line, `MethodInfo::explicit("Dopri5", (5, 4), 4, 3.3)`, and states
/// only where it departs from its family (`with_controller`, `with_control_order`) and what to try
/// when it fails (`with_advice`; the conformance suite checks that every method has advice).
impl MethodInfo {
    /// An explicit embedded pair of orders `p(p̂)` (`(5, 4)` for Dormand–Prince 5(4)) with dense
    /// output of order `dense_order` and stability size `stability_size`: no Jacobian, step-size
    /// control with exponent `q = p̂ + 1` by the classical controller, ratios in `[0.2, 10]`.
    pub const fn explicit(
        name: &'static str,
        (order, embedded): (u32, u32),
        dense_order: u32,
        stability_size: f64,
    ) -> Self {
        Self {
            name,
            order,
            embedded_order: Some(embedded),
            control_order: embedded.saturating_add(1),
            dense_order,
            stability_size,
            needs_jacobian: false,
            fixed_step: None,
            controller: Controller::i(0.2, 10.0),
            advice: "",
        }
    }

    /// A Rosenbrock (linearly implicit) embedded pair of orders `p(p̂)`, A-stable: as
    /// [`MethodInfo::explicit`] with an unbounded stability size and the Jacobian evaluated.
    pub const fn rosenbrock(name: &'static str, orders: (u32, u32), dense_order: u32) -> Self {
        let mut info = Self::explicit(name, orders, dense_order, f64::INFINITY);
        info.needs_jacobian = true;
        info
    }

    /// An explicit method of order `order` without error control, stepping by `h`.
    pub const fn fixed_step(
        name: &'static str,
        order: u32,
        dense_order: u32,
        stability_size: f64,
        h: f64,
    ) -> Self {
        let embedded = order.saturating_sub(1);
        let mut info = Self::explicit(name, (order, embedded), dense_order, stability_size);
        info.embedded_order = None;
        info.fixed_step = Some(h);
        info
    }

    /// The same facts with another step-size controller.
    pub const fn with_controller(mut self, controller: Controller) -> Self {
        self.controller = controller;
        self
    }

    /// The same facts with another exponent of step-size control (DOP853's combined estimate
    /// calls for its order, not the embedded order plus one).
    pub const fn with_control_order(mut self, control_order: u32) -> Self {
        self.control_order = control_order;
        self
    }

    /// The same facts with the advice shown when the method fails.
    pub const fn with_advice(mut self, advice: &'static str) -> Self {
        self.advice = advice;
        self
    }

    /// Checks that the facts are complete and consistent with one another, as the driver needs
    /// them: a name and advice; orders `1 ≤ p`, an embedded order below `p`, control and dense
    /// orders in `1..=p`; a positive stability size, unbounded exactly for a method that needs the
    /// Jacobian; a fixed step (finite and positive) exactly for a method without an embedded
    /// solution; a valid controller. The driver checks them before it steps.
    pub fn validate(&self) -> Result<(), Error> {
        let fail = |name: &'static str, value: f64, hint: &'static str| {
            Err(Error::InvalidOption { name, value, hint })
        };
        let p = self.order;
        if self.name.is_empty() || self.advice.is_empty() {
            return fail(
                "MethodInfo::name, advice",
                0.0,
                "a method names itself and says what to try when it fails (`with_advice`)",
            );
        }
        let orders_ok = p >= 1
            && self.embedded_order.is_none_or(|e| e < p)
            && (1..=p).contains(&self.control_order)
            && (1..=p).contains(&self.dense_order);
        if !orders_ok {
            return fail(
                "MethodInfo::order",
                f64::from(p),
                "orders of at least 1, the embedded order below the order, control and dense \
                 orders between 1 and the order",
            );
        }
        // Positive, and not NaN.
        let positive = self.stability_size > 0.0;
        if !positive || self.stability_size.is_infinite() != self.needs_jacobian {
            return fail(
                "MethodInfo::stability_size",
                self.stability_size,
                "a positive size, infinite exactly for a method that needs the Jacobian (an \
                 A-stable implicit method)",
            );
        }
        match (self.embedded_order, self.fixed_step) {
            (None, Some(h)) if h.is_finite() && h > 0.0 => {}
            (Some(_), None) => {}
            (_, h) => {
                return fail(
                    "MethodInfo::fixed_step",
                    h.unwrap_or(f64::NAN),
                    "a finite positive step for a method without an embedded solution, none for \
                     one with it",
                )
            }
        }
        self.controller.validate()
    }
}

/// A step-size controller: after a step with weighted error `err` (`≤ 1` accepts), the next step is
///
/// ```text
/// h_new = h · clamp(safety · err^(−α) · err_prev^β, fac_min, fac_max),   α = 1/q − 0.75 β,
/// ```
///
/// with `q` the method's control order and `err_prev` the error of the last accepted step (at least
/// `1e-4`). `β = 0` is the classical (I) controller; `β > 0` is the PI controller of Gustafsson as
/// in Hairer's DOPRI5 (Hairer, Nørsett, Wanner I, Section II.4, and IV.2 for `β = 0.04`). After a
/// rejection the step never grows, and a rejected step shrinks by `clamp(safety · err^(−α),
/// fac_min, 1)`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Controller {
    /// Safety factor (Hairer's `SAFE`, 0.9).
    pub safety: f64,
    /// Smallest step ratio (Hairer's `1/FAC1`... his `FAC1`: 0.2 in DOPRI5, 0.333 in DOP853).
    pub fac_min: f64,
    /// Largest step ratio (Hairer's `FAC2`: 10 in DOPRI5, 6 in DOP853).
    pub fac_max: f64,
    /// The PI controller's `β` (Hairer's `BETA`; 0 for the I controller).
    pub beta: f64,
}

impl Controller {
    /// The classical controller with safety 0.9 and step ratios in `[fac_min, fac_max]`.
    pub const fn i(fac_min: f64, fac_max: f64) -> Self {
        Self {
            safety: 0.9,
            fac_min,
            fac_max,
            beta: 0.0,
        }
    }

    /// The PI controller with safety 0.9, step ratios in `[fac_min, fac_max]` and `β`.
    pub const fn pi(fac_min: f64, fac_max: f64, beta: f64) -> Self {
        Self {
            safety: 0.9,
            fac_min,
            fac_max,
            beta,
        }
    }

    /// Checks the controller's numbers.
    pub fn validate(&self) -> Result<(), Error> {
        let ok = self.safety > 0.0
            && self.safety <= 1.0
            && self.fac_min > 0.0
            && self.fac_min < 1.0
            && self.fac_max > 1.0
            && self.fac_max.is_finite()
            && (0.0..0.2).contains(&self.beta);
        if ok {
            Ok(())
        } else {
            Err(Error::InvalidOption {
                name: "controller",
                value: self.safety,
                hint: "a controller needs 0 < safety ≤ 1, 0 < fac_min < 1 < fac_max < ∞ and 0 ≤ β < 0.2 \
                       (Hairer's codes: safety 0.9, factors 0.2 and 10, β = 0.04)",
            })
        }
    }

    /// The step ratio after an accepted step with error `err`, with `alpha = 1/q − 0.75 β`.
    #[inline]
    pub(crate) fn accepted(&self, err: f64, err_prev: f64, q: u32, rejected_last: bool) -> f64 {
        let alpha = 1.0 / q as f64 - 0.75 * self.beta;
        let fac_max = if rejected_last { 1.0 } else { self.fac_max };
        if err <= 0.0 {
            return fac_max;
        }
        let mut fac = self.safety * err.powf(-alpha);
        if self.beta != 0.0 {
            fac *= err_prev.powf(self.beta);
        }
        fac.clamp(self.fac_min, fac_max)
    }

    /// The step ratio after a rejected step with error `err > 1`.
    #[inline]
    pub(crate) fn rejected(&self, err: f64, q: u32) -> f64 {
        let alpha = 1.0 / q as f64 - 0.75 * self.beta;
        (self.safety * err.powf(-alpha)).clamp(self.fac_min, 1.0)
    }
}

/// A named integration method from the literature, with its options.
pub trait Method {
    /// The stepper it runs.
    type Stepper: Stepper;
    /// The method's facts.
    fn info(&self) -> MethodInfo;
    /// A stepper for a system of dimension `dim`, with its work vectors allocated once.
    fn stepper(&self, dim: usize) -> Self::Stepper;
    /// Checks the method's own options.
    fn validate(&self) -> Result<(), Error> {
        Ok(())
    }
    /// The method's name, as in the literature.
    fn name(&self) -> &'static str {
        self.info().name
    }
    /// The settings of the method's stiffness test, for a method that has one (`None`, the
    /// default, for the others).
    fn stiffness_detection_mut(&mut self) -> Option<&mut StiffnessDetection> {
        None
    }
}

/// A trial step of size `h` from `(t, y)`: the stepper writes the new state to `y_new` and
/// measures its error estimate with `norm`.
#[derive(Debug)]
pub struct Trial<'a> {
    /// The start of the step.
    pub t: f64,
    /// The step size (negative when integrating backward).
    pub h: f64,
    /// The state at `t`.
    pub y: &'a [f64],
    /// The state at `t + h`, written by the step.
    pub y_new: &'a mut [f64],
    /// The norm of error control.
    pub norm: &'a ErrorNorm,
}

impl<'a> Trial<'a> {
    /// `(t, h, y, y_new, norm)`.
    pub fn parts(self) -> (f64, f64, &'a [f64], &'a mut [f64], &'a ErrorNorm) {
        (self.t, self.h, self.y, self.y_new, self.norm)
    }
}

/// A step of size `h` from `(t, y)` to `(t + h, y_new)`.
#[derive(Clone, Copy, Debug)]
pub struct Step<'a> {
    /// The start of the step.
    pub t: f64,
    /// The step size.
    pub h: f64,
    /// The state at `t`.
    pub y: &'a [f64],
    /// The state at `t + h`.
    pub y_new: &'a [f64],
}

/// One integration method's step, error estimate and dense output.
pub trait Stepper {
    /// Prepares stepping from `(t, y)` (evaluates `F(t, y)` where the method reuses it). Called
    /// before the first step and whenever the state was changed from outside (projection).
    fn reset<S: OdeSystem>(&mut self, sys: &mut S, t: f64, y: &[f64]) -> Result<(), Error>;
    /// Attempts the trial step: writes its result to `y_new` and returns the error estimate
    /// measured with `norm` (`≤ 1` means acceptable; `0` for fixed-step methods).
    fn attempt<S: OdeSystem>(&mut self, sys: &mut S, trial: Trial<'_>) -> Result<f64, Error>;
    /// The attempted step was accepted: prepare dense output on `[t, t + h]` and the next step.
    /// The last evaluation of `F` here (or in [`Stepper::attempt`], where this makes none) must be
    /// at the end of the step, `t + h`, where [`OdeSystem::accepted`] checks what it evaluated;
    /// evaluations that only the dense output needs go in [`Stepper::extend`].
    fn commit<S: OdeSystem>(&mut self, sys: &mut S, step: Step<'_>) -> Result<(), Error>;
    /// After the end of the accepted step was checked: the evaluations only the dense output
    /// needs (Dop853's three extra stages). The default makes none.
    fn extend<S: OdeSystem>(&mut self, sys: &mut S, step: Step<'_>) -> Result<(), Error> {
        let _ = (sys, step);
        Ok(())
    }
    /// [`Stepper::attempt`] with the trial's parts as arguments.
    fn try_step<S: OdeSystem>(
        &mut self,
        sys: &mut S,
        t: f64,
        h: f64,
        y: &[f64],
        y_new: &mut [f64],
        norm: &ErrorNorm,
    ) -> Result<f64, Error> {
        self.attempt(
            sys,
            Trial {
                t,
                h,
                y,
                y_new,
                norm,
            },
        )
    }
    /// Accepts the step from `(t, y)` to `(t + h, y_new)`: [`Stepper::commit`], the system's check
    /// of the step's end ([`OdeSystem::accepted`]), then [`Stepper::extend`].
    fn accept<S: OdeSystem>(
        &mut self,
        sys: &mut S,
        t: f64,
        h: f64,
        y: &[f64],
        y_new: &[f64],
    ) -> Result<(), Error> {
        let step = Step { t, h, y, y_new };
        self.commit(sys, step)?;
        sys.accepted(t + h, y_new)?;
        self.extend(sys, step)
    }
    /// The dense output `y(t + θh)`, `θ ∈ [0, 1]`, of the last accepted step.
    fn interpolate(&self, theta: f64, out: &mut [f64]);
    /// Whether anything will call [`Stepper::interpolate`] (output at requested times, events).
    /// A method whose dense output costs extra work may skip it when not; the default ignores it.
    fn set_dense_output(&mut self, needed: bool) {
        let _ = needed;
    }
    /// `Some(h·|λ|)` when the method has detected stiffness on the last steps.
    fn stiffness(&self) -> Option<f64> {
        None
    }
}

/// The list of methods: one line each, `Name = how it is made with default options`, where
/// `step?` is the fixed step of a method without error control. Everything that runs over every
/// method ([`AnyMethod`], [`AnyStepper`], their `match`es, [`AnyMethod::all`],
/// [`AnyMethod::from_name`], the conformance suite) is generated from it.
macro_rules! method_list {
    ($step:ident; $($name:ident = $make:expr,)+) => {
        /// Every method of the crate as one value, for choosing a method at run time (scene files,
        /// command lines, sweeps). It is itself a [`Method`]:
        /// `solve(&problem, AnyMethod::Dop853(Dop853::default()), &options)`. With the `serde`
        /// feature it is (de)serialisable, as `{"method": "dop853"}` and the method's options
        /// beside it.
        #[derive(Clone, Copy, Debug, PartialEq)]
        #[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
        #[cfg_attr(feature = "serde", serde(tag = "method", rename_all = "lowercase"))]
        #[non_exhaustive]
        pub enum AnyMethod {
            $(
                #[doc = concat!("[`", stringify!($name), "`].")]
                $name($name),
            )+
        }

        /// The stepper of an [`AnyMethod`]. Made once per solve, so the size of its largest
        /// variant (Dop853's sixteen stage vectors, held by value) costs nothing that matters.
        #[derive(Clone, Debug)]
        #[allow(clippy::large_enum_variant)]
        pub enum AnyStepper {
            $(
                #[doc = concat!("[`", stringify!($name), "`]'s.")]
                $name(<$name as Method>::Stepper),
            )+
        }

        impl AnyMethod {
            /// The names of the methods, as in the literature, in the order of the list; lower
            /// case, they are the keys of [`AnyMethod::from_name`], scene files and serde.
            pub const NAMES: &'static [&'static str] = &[$(stringify!($name)),+];

            /// The method of this name (case-insensitive, one of [`AnyMethod::NAMES`]) with
            /// default options; a method without error control (`rk4`) takes its step
            /// `fixed_step`, which the others ignore.
            pub fn from_name(name: &str, fixed_step: Option<f64>) -> Result<AnyMethod, Error> {
                $(
                    if name.eq_ignore_ascii_case(stringify!($name)) {
                        let $step = fixed_step.ok_or(Error::InvalidOption {
                            name: concat!(stringify!($name), "::h"),
                            value: f64::NAN,
                            hint: "a method without error control has a fixed step: give its \
                                   step size",
                        });
                        let _ = &$step;
                        return Ok(AnyMethod::$name($make));
                    }
                )+
                Err(Error::UnknownMethod {
                    name: name.to_string(),
                    choices: Self::choices(),
                })
            }
        }

        impl Method for AnyMethod {
            type Stepper = AnyStepper;
            fn info(&self) -> MethodInfo {
                match self {
                    $(AnyMethod::$name(m) => m.info(),)+
                }
            }
            fn stepper(&self, dim: usize) -> AnyStepper {
                match self {
                    $(AnyMethod::$name(m) => AnyStepper::$name(m.stepper(dim)),)+
                }
            }
            fn validate(&self) -> Result<(), Error> {
                match self {
                    $(AnyMethod::$name(m) => m.validate(),)+
                }
            }
            fn stiffness_detection_mut(&mut self) -> Option<&mut StiffnessDetection> {
                match self {
                    $(AnyMethod::$name(m) => m.stiffness_detection_mut(),)+
                }
            }
        }

        impl Stepper for AnyStepper {
            fn reset<S: OdeSystem>(&mut self, sys: &mut S, t: f64, y: &[f64]) -> Result<(), Error> {
                match self {
                    $(AnyStepper::$name(s) => s.reset(sys, t, y),)+
                }
            }
            fn attempt<S: OdeSystem>(
                &mut self,
                sys: &mut S,
                trial: Trial<'_>,
            ) -> Result<f64, Error> {
                match self {
                    $(AnyStepper::$name(s) => s.attempt(sys, trial),)+
                }
            }
            fn commit<S: OdeSystem>(&mut self, sys: &mut S, step: Step<'_>) -> Result<(), Error> {
                match self {
                    $(AnyStepper::$name(s) => s.commit(sys, step),)+
                }
            }
            fn extend<S: OdeSystem>(&mut self, sys: &mut S, step: Step<'_>) -> Result<(), Error> {
                match self {
                    $(AnyStepper::$name(s) => s.extend(sys, step),)+
                }
            }
            fn interpolate(&self, theta: f64, out: &mut [f64]) {
                match self {
                    $(AnyStepper::$name(s) => s.interpolate(theta, out),)+
                }
            }
            fn set_dense_output(&mut self, needed: bool) {
                match self {
                    $(AnyStepper::$name(s) => s.set_dense_output(needed),)+
                }
            }
            fn stiffness(&self) -> Option<f64> {
                match self {
                    $(AnyStepper::$name(s) => s.stiffness(),)+
                }
            }
        }
    };
}

method_list! {
    step;
    Dopri5 = Dopri5::default(),
    Dop853 = Dop853::default(),
    Tsit5 = Tsit5::default(),
    Rk4 = Rk4::new(step?),
    Rodas4 = Rodas4,
    Rodas5P = Rodas5P,
}

impl AnyMethod {
    /// Every method of the list with its default options (a method without error control with
    /// step `fixed_step`), in the order of [`AnyMethod::NAMES`]. The conformance suite runs on
    /// each.
    pub fn all(fixed_step: f64) -> Vec<AnyMethod> {
        Self::NAMES
            .iter()
            .filter_map(|name| Self::from_name(name, Some(fixed_step)).ok())
            .collect()
    }

    /// The keys of [`AnyMethod::from_name`], "dopri5, dop853, …", a method without error control
    /// marked "(with its step)".
    fn choices() -> String {
        Self::all(1.0)
            .iter()
            .map(|m| {
                let info = m.info();
                let key = info.name.to_lowercase();
                match info.fixed_step {
                    Some(_) => format!("{key} (with its step)"),
                    None => key,
                }
            })
            .collect::<Vec<_>>()
            .join(", ")
    }
}

/// The weighted RMS norm of error control: `sqrt(mean_i (e_i / (atol_i + rtol·max(|y_i|, |ŷ_i|)))²)`
/// over the controlled components.
#[derive(Clone, Debug)]
pub struct ErrorNorm {
    rtol: f64,
    atol: Vec<f64>,
}

impl ErrorNorm {
    /// A norm with one relative tolerance and one absolute tolerance per controlled component.
    ///
    /// An absolute tolerance below the smallest normal number is taken as that number, so every
    /// scale is positive: a component held at exactly zero under a purely relative tolerance
    /// (`atol_i = 0`) counts no error where it has none, instead of `0/0`. Larger tolerances are
    /// kept as given.
    pub fn new(rtol: f64, atol: Vec<f64>) -> Self {
        let atol = atol.into_iter().map(|a| a.max(f64::MIN_POSITIVE)).collect();
        Self { rtol, atol }
    }

    /// The scale `atol_i + rtol·max(|y_i|, |ŷ_i|)` of component `i` (positive, see
    /// [`ErrorNorm::new`]).
    #[inline(always)]
    pub fn scale(&self, i: usize, y: f64, y_new: f64) -> f64 {
        self.atol[i] + self.rtol * y.abs().max(y_new.abs())
    }

    /// `Σ_i (e_i / sc_i)²` over the controlled components.
    #[inline]
    pub fn sum_sq(&self, e: &[f64], y: &[f64], y_new: &[f64]) -> f64 {
        let mut s = 0.0;
        for i in 0..self.atol.len() {
            let r = e[i] / self.scale(i, y[i], y_new[i]);
            s += r * r;
        }
        s
    }

    /// The weighted RMS norm of `e`.
    #[inline]
    pub fn norm(&self, e: &[f64], y: &[f64], y_new: &[f64]) -> f64 {
        (self.sum_sq(e, y, y_new) / self.atol.len() as f64).sqrt()
    }

    /// The weighted RMS norm of the error estimate `e = h Σ_s w_s k_s` of an embedded pair, with
    /// `w_s = b_s − b̂_s` over the stages `k`: formed, weighted and summed in one pass, so no error
    /// vector is stored.
    #[inline(always)]
    pub(crate) fn of_combination<const S: usize>(
        &self,
        h: f64,
        w: &[f64; S],
        k: &[&[f64]; S],
        y: &[f64],
        y_new: &[f64],
    ) -> f64 {
        let mut sum = 0.0;
        for i in 0..self.atol.len() {
            let e = h * weighted(w, k, i);
            let r = e / self.scale(i, y[i], y_new[i]);
            sum += r * r;
        }
        (sum / self.atol.len() as f64).sqrt()
    }

    /// Number of controlled components.
    pub fn len(&self) -> usize {
        self.atol.len()
    }

    /// Whether no component is controlled.
    pub fn is_empty(&self) -> bool {
        self.atol.is_empty()
    }
}

/// A row of an explicit Runge–Kutta tableau: the node `c_i` of stage `i` and its coefficients
/// `a_ij` over the earlier stages it combines (those with `a_ij ≠ 0`, in order).
#[derive(Clone, Copy, Debug)]
pub(crate) struct Stage<const S: usize> {
    pub(crate) c: f64,
    pub(crate) a: [f64; S],
}

impl<const S: usize> Stage<S> {
    /// Evaluates the stage at `(t, h, y)`: its argument `arg = y + h Σ_j a_ij k_j` over the earlier
    /// stages `k`, then `out = F(t + c_i h, arg)`.
    #[inline(always)]
    pub(crate) fn eval<Sy: OdeSystem>(
        &self,
        sys: &mut Sy,
        (t, h, y): (f64, f64, &[f64]),
        k: [&[f64]; S],
        arg: &mut [f64],
        out: &mut [f64],
    ) -> Result<(), Error> {
        combine(arg, y, h, &self.a, k);
        sys.rhs(t + self.c * h, arg, out)
    }
}

/// Stages 2 to 6 of a seven-stage explicit pair of order 5(4) whose stages each combine all the
/// earlier ones, stage 6 sitting at `c_6 = 1` and stage 7 being the derivative at the new point
/// (first same as last): Dormand–Prince 5(4) and Tsitouras 5(4) have this shape.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Stages54 {
    pub(crate) s2: Stage<1>,
    pub(crate) s3: Stage<2>,
    pub(crate) s4: Stage<3>,
    pub(crate) s5: Stage<4>,
    pub(crate) s6: Stage<5>,
}

impl Stages54 {
    /// `k_2..k_6` of the step `(t, h, y)` from `k_1` (the first of `k`): the arguments of stages 2
    /// to 5 are formed in `arg`, that of stage 6 in `arg6` (a method that needs it afterwards, as
    /// the stiffness test does, keeps it there).
    #[inline(always)]
    pub(crate) fn eval<Sy: OdeSystem>(
        &self,
        sys: &mut Sy,
        at: (f64, f64, &[f64]),
        [k1, k2, k3, k4, k5, k6]: [&mut [f64]; 6],
        arg: &mut [f64],
        arg6: &mut [f64],
    ) -> Result<(), Error> {
        self.s2.eval(sys, at, [k1], arg, k2)?;
        self.s3.eval(sys, at, [k1, k2], arg, k3)?;
        self.s4.eval(sys, at, [k1, k2, k3], arg, k4)?;
        self.s5.eval(sys, at, [k1, k2, k3, k4], arg, k5)?;
        self.s6.eval(sys, at, [k1, k2, k3, k4, k5], arg6, k6)
    }
}

/// The shortest step that still changes `t`: 4 ulps of it. The step loop stops with
/// [`Error::StepSizeTooSmall`](crate::Error::StepSizeTooSmall) below it, and a fixed step or a
/// `max_step` below it somewhere in the interval is refused before the run.
pub(crate) fn time_resolution(t: f64) -> f64 {
    4.0 * f64::EPSILON * t.abs()
}

/// `out = y + h Σ_s a_s k_s` over the stages `k` with the coefficients `a`.
#[inline(always)]
pub(crate) fn combine<const S: usize>(
    out: &mut [f64],
    y: &[f64],
    h: f64,
    a: &[f64; S],
    k: [&[f64]; S],
) {
    for i in 0..out.len() {
        let mut acc = 0.0;
        for (a, k) in a.iter().zip(&k) {
            acc += a * k[i];
        }
        out[i] = y[i] + h * acc;
    }
}

/// The work vectors of a stepper, `count` of length `dim`, in one allocation (a short solve would
/// otherwise spend a noticeable part of its time allocating them one by one).
#[derive(Clone, Debug)]
pub(crate) struct Pool {
    data: Vec<f64>,
    dim: usize,
}

impl Pool {
    /// `count` zeroed vectors of length `dim`.
    pub(crate) fn new(count: usize, dim: usize) -> Self {
        Self {
            data: vec![0.0; count * dim],
            dim,
        }
    }

    /// All `M` vectors, as disjoint mutable slices.
    #[inline(always)]
    pub(crate) fn all<const M: usize>(&mut self) -> [&mut [f64]; M] {
        let mut chunks = self.data.chunks_exact_mut(self.dim.max(1));
        std::array::from_fn(|_| chunks.next().unwrap_or_default())
    }

    /// Vector `i`.
    #[inline(always)]
    pub(crate) fn get(&self, i: usize) -> &[f64] {
        &self.data[i * self.dim..(i + 1) * self.dim]
    }

    /// Vector `i`, mutable.
    #[inline(always)]
    pub(crate) fn get_mut(&mut self, i: usize) -> &mut [f64] {
        &mut self.data[i * self.dim..(i + 1) * self.dim]
    }
}

/// `Σ_s a_s k_s[i]`, summed from the first term on (as `a_1 k_1[i] + a_2 k_2[i] + …` reads).
#[inline(always)]
pub(crate) fn weighted<const S: usize>(a: &[f64; S], k: &[&[f64]; S], i: usize) -> f64 {
    let mut acc = a[0] * k[0][i];
    for (s, k) in k.iter().enumerate().skip(1) {
        acc += a[s] * k[i];
    }
    acc
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn any_method_names_round_trip() -> Result<(), Error> {
        let all = AnyMethod::all(0.01);
        assert_eq!(
            all.len(),
            AnyMethod::NAMES.len(),
            "every listed method is made"
        );
        for (m, listed) in all.iter().zip(AnyMethod::NAMES) {
            // The list's name is the method's own, the key of scene files and serde.
            assert_eq!(m.name(), *listed);
            let name = m.name().to_ascii_lowercase();
            let back = AnyMethod::from_name(&name, Some(0.01))?;
            assert_eq!(back.info(), m.info());
            // The step is required exactly by the methods without error control.
            let needs_step = m.info().fixed_step.is_some();
            match AnyMethod::from_name(&name, None) {
                Err(Error::InvalidOption { name: option, .. }) => {
                    assert!(needs_step, "{listed}");
                    assert_eq!(option, format!("{listed}::h"));
                }
                Ok(_) => assert!(!needs_step, "{listed}"),
                Err(e) => panic!("{listed}: {e}"),
            }
        }
        // The unknown name is refused with the list's names, a fixed-step method's marked.
        match AnyMethod::from_name("euler", None) {
            Err(e @ Error::UnknownMethod { .. }) => {
                let text = e.to_string();
                assert!(text.starts_with("unknown method \"euler\": choose one of dopri5, "));
                for m in &all {
                    let key = m.name().to_ascii_lowercase();
                    match m.info().fixed_step {
                        Some(_) => assert!(text.contains(&format!("{key} (with its step)"))),
                        None => assert!(text.contains(&key), "{text}"),
                    }
                }
            }
            other => panic!("{other:?}"),
        }
        Ok(())
    }

    /// A method of someone else's whose facts the driver could not use.
    struct Misdeclared(MethodInfo);

    impl Method for Misdeclared {
        type Stepper = dopri5::Dopri5Stepper;
        fn info(&self) -> MethodInfo {
            self.0
        }
        fn stepper(&self, dim: usize) -> Self::Stepper {
            Dopri5::default().stepper(dim)
        }
    }

    #[test]
    fn inconsistent_method_facts_are_refused_with_what_was_wrong() {
        let good = Dopri5::default().info();
        let bad = [
            ("MethodInfo::name, advice", good.with_advice("")),
            ("MethodInfo::order", MethodInfo { order: 0, ..good }),
            ("MethodInfo::order", good.with_control_order(0)),
            (
                "MethodInfo::order",
                MethodInfo::explicit("X", (4, 4), 3, 1.0).with_advice("a"),
            ),
            (
                "MethodInfo::order",
                MethodInfo {
                    dense_order: 6,
                    ..good
                },
            ),
            (
                "MethodInfo::stability_size",
                MethodInfo {
                    stability_size: f64::NAN,
                    ..good
                },
            ),
            (
                "MethodInfo::stability_size",
                MethodInfo {
                    needs_jacobian: true,
                    ..good
                },
            ),
            (
                "MethodInfo::fixed_step",
                MethodInfo {
                    fixed_step: Some(0.1),
                    ..good
                },
            ),
        ];
        for (name, info) in &bad {
            let e = info.validate();
            assert!(
                matches!(e, Err(Error::InvalidOption { name: n, .. }) if n == *name),
                "{info:?}: {e:?}"
            );
        }
        let no_step = MethodInfo::fixed_step("X", 4, 3, 2.78, f64::NAN).with_advice("a");
        assert!(matches!(
            no_step.validate(),
            Err(Error::InvalidOption {
                name: "MethodInfo::fixed_step",
                ..
            })
        ));
        let pi = Controller::pi(0.2, 10.0, 0.5);
        assert!(good.with_controller(pi).validate().is_err());
        // The same reaches a caller of the driver as the error, before any step.
        let mut sys = testing::Sys::explicit(1, |_, y: &[f64], dy: &mut [f64]| dy[0] = -y[0]);
        let options = driver::OdeOptions::until(1.0);
        let method = Misdeclared(good.with_control_order(0));
        let e = driver::solve_ode(&mut sys, method, 0.0, &[1.0], &options);
        assert!(matches!(
            e,
            Err(Error::InvalidOption {
                name: "MethodInfo::order",
                ..
            })
        ));
        assert_eq!(sys.rhs_evaluations, 0);
        assert!(driver::solve_ode(&mut sys, Misdeclared(good), 0.0, &[1.0], &options).is_ok());
    }

    #[cfg(feature = "serde")]
    #[test]
    fn any_method_serialises_with_its_options() -> Result<(), Box<dyn std::error::Error>> {
        for m in AnyMethod::all(0.01) {
            let text = serde_json::to_string(&m)?;
            let back: AnyMethod = serde_json::from_str(&text)?;
            assert_eq!(back, m, "{text}");
        }
        let m: AnyMethod = serde_json::from_str(r#"{"method": "dop853"}"#)?;
        assert_eq!(m, AnyMethod::Dop853(Dop853::default()));
        // The stiffness test's settings stand beside the name, each defaulting on its own.
        let m: AnyMethod =
            serde_json::from_str(r#"{"method": "dopri5", "stiffness_detection": false}"#)?;
        assert_eq!(
            m,
            AnyMethod::Dopri5(Dopri5 {
                stiffness: StiffnessDetection::OFF
            })
        );
        let m: AnyMethod =
            serde_json::from_str(r#"{"method": "tsit5", "stiffness_detection": false}"#)?;
        assert_eq!(
            m,
            AnyMethod::Tsit5(Tsit5 {
                stiffness: StiffnessDetection::OFF
            })
        );
        let m: AnyMethod = serde_json::from_str(r#"{"method": "tsit5"}"#)?;
        assert_eq!(m, AnyMethod::Tsit5(Tsit5::default()));
        let mut every = AnyMethod::Dop853(Dop853::default());
        if let Some(s) = every.stiffness_detection_mut() {
            s.interval = 7;
        }
        let text = serde_json::to_string(&every)?;
        assert_eq!(
            text,
            r#"{"method":"dop853","stiffness_detection":true,"stiffness_interval":7}"#
        );
        assert_eq!(serde_json::from_str::<AnyMethod>(&text)?, every);
        Ok(())
    }
}
