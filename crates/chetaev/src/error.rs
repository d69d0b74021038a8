//! The one error type of the crate.
//!
//! Setup problems (bad input) are returned as `Err` by the constructors and by
//! [`solve`](crate::solve); failures during an integration are stored as the status of the
//! returned [`Solution`](crate::Solution), together with everything computed up to that point.

/// Everything that can go wrong, with the numbers that explain it and what to try next.
///
/// Its `Debug` form is its message, so that `fn main() -> Result<(), chetaev::Error>` and `{:?}`
/// print what was wrong and what to try, not a struct dump; the fields are public for code.
#[cfg_attr(feature = "serde", derive(serde::Serialize))]
#[derive(Clone, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum Error {
    /// An input number is NaN or infinite.
    #[error("{what} is not finite ({value}); every parameter, time and initial value must be a finite number", value = Num(*.value))]
    NonFiniteInput {
        /// Which input.
        what: String,
        /// Its value.
        value: f64,
    },

    /// A solver option is out of range.
    #[error("invalid option {name} = {value}: {hint}", value = Num(*.value))]
    InvalidOption {
        /// The option.
        name: &'static str,
        /// Its value.
        value: f64,
        /// The allowed range, and what to use instead.
        hint: &'static str,
    },

    /// The dependent coordinates or speeds of a state could not be solved from the independent
    /// ones ([`manifold::complete`](crate::manifold::complete)).
    #[error(
        "completing the dependent {stage} failed at {row}: relative residual {residual} after {iterations} Newton iterations; {why}",
        row = Row(*.constraint, *.holonomic), residual = Num(*.residual)
    )]
    Completion {
        /// `"coordinates"` (from `h = 0`) or `"speeds"` (from `f = 0` and `ḣ = 0`).
        stage: &'static str,
        /// The row that was worst when it stopped, numbered from 1 among the velocity-level rows
        /// (velocity constraints, then `ḣ`), or for the coordinates the holonomic one's row.
        constraint: usize,
        /// For a holonomic constraint, its number among the holonomic ones, from 1.
        holonomic: Option<usize>,
        /// That row's residual relative to its scale.
        residual: f64,
        /// Newton iterations done.
        iterations: usize,
        /// Why, and what to try.
        why: String,
    },

    /// The model's sizes or the initial state's lengths are wrong.
    #[error("invalid model: {what}")]
    InvalidModel {
        /// What is wrong, and what to do.
        what: String,
    },

    /// No method has this name.
    #[error("unknown method \"{name}\": choose one of {choices}")]
    UnknownMethod {
        /// The name given.
        name: String,
        /// The names there are, from the method list.
        choices: String,
    },

    /// An output time lies outside the integration interval.
    #[error(
        "output time {time} lies outside the integration interval from t0 = {t0} to t_end = {t_end}; \
         give output times between the start and the end time",
        t0 = Num(*.t0), t_end = Num(*.t_end), time = Num(*.time)
    )]
    OutputTimeOutOfRange {
        /// The output time.
        time: f64,
        /// The start time.
        t0: f64,
        /// The end time.
        t_end: f64,
    },

    /// The initial velocity does not satisfy the constraints: a velocity constraint `f_a = 0`, or
    /// the time derivative `ḣ_b = ∂h_b/∂q·q̇ + ∂h_b/∂t = 0` of a holonomic one.
    #[error(
        "the initial velocity violates {row}{value} = {residual:e} at t = {t} (allowed {tolerance:.2e}); \
         give {what}, or opt in to Problem::with_projected_velocity to project it onto {target} = 0",
        row = Row(*.index, *.holonomic),
        value = if .holonomic.is_some() {
            " differentiated in time: ḣ = ∂h/∂q·q̇ + ∂h/∂t"
        } else {
            ": f"
        },
        t = Num(*.t),
        what = if .holonomic.is_some() {
            "a q̇0 along the holonomic constraints (ḣ = 0: the motion would leave h = 0 at once)"
        } else {
            "a consistent initial velocity"
        },
        target = if .holonomic.is_some() { "ḣ" } else { "f" }
    )]
    InconsistentInitialState {
        /// Initial time.
        t: f64,
        /// The row's number, from 1: the velocity constraints first, then the holonomic ones.
        index: usize,
        /// For a holonomic constraint, its number among the holonomic ones (from 1); `None` for
        /// a velocity constraint.
        holonomic: Option<usize>,
        /// `f_a(t0, q0, q̇0)`, or `ḣ_b(t0, q0, q̇0)`.
        residual: f64,
        /// The largest residual accepted.
        tolerance: f64,
    },

    /// The initial position does not satisfy a holonomic constraint.
    #[error(
        "the initial position violates holonomic constraint {index} (numbered from 1 among the holonomic \
         ones): h = {residual:e} at t = {t} (allowed {tolerance:.2e}); give a consistent initial position, or \
         opt in to Problem::with_projected_velocity, which projects the position onto h = 0 and then the \
         velocity",
        t = Num(*.t)
    )]
    InconsistentInitialPosition {
        /// Initial time.
        t: f64,
        /// The holonomic constraint's number, from 1.
        index: usize,
        /// `h_b(t0, q0)`.
        residual: f64,
        /// The largest residual accepted.
        tolerance: f64,
    },

    /// The holonomic constraints are redundant at the initial position: the gradient
    /// `∂h_b/∂q` of one is a combination of the others' (the same constraint given twice, or `h`
    /// and `2h`), so the constraints hold no more than the others do and their multipliers are
    /// not determined.
    #[error(
        "holonomic constraints {list} (numbered from 1 among the holonomic ones) are redundant at \
         the initial position, t = {t}: the gradient ∂h/∂q of constraint {index} is a combination \
         of those of {others} (the same constraint given twice, or one a multiple of another, such \
         as h and 2h), so their multipliers are not determined; remove constraint {index}, or \
         another of them",
        t = Num(*.t),
        list = Numbers(&std::iter::once(*.index).chain(.dependent_on.iter().copied()).collect::<Vec<_>>()),
        others = Numbers(.dependent_on),
    )]
    RedundantHolonomic {
        /// Initial time.
        t: f64,
        /// The holonomic constraint whose gradient depends on the others', numbered from 1.
        index: usize,
        /// The holonomic constraints (numbered from 1, before `index`) whose gradients it is a
        /// combination of.
        dependent_on: Vec<usize>,
    },

    /// The block system for `q̈` and `μ` is singular.
    #[error(
        "the Chetaev block system is singular at t = {t} (pivot ratio {pivot_ratio:e}) with q = {q:?}, q̇ = {qd:?}: \
         the constraint Jacobian ∂f/∂q̇ has lost rank (a repeated constraint, or a zero velocity under a constraint \
         on its magnitude) or ∂²L/∂q̇² is singular on the constraints' tangent space (a coordinate without kinetic energy)",
        t = Num(*.t)
    )]
    Singular {
        /// Time.
        t: f64,
        /// Smallest over largest pivot magnitude.
        pivot_ratio: f64,
        /// Position.
        q: Vec<f64>,
        /// Velocity.
        qd: Vec<f64>,
    },

    /// A constraint's gradient `∂f_a/∂q̇` vanishes.
    #[error(
        "constraint {index} (numbered from 1) has ∂f/∂q̇ = 0 at t = {t} with q = {q:?}, q̇ = {qd:?}: it does not \
         restrict the velocity there: a constraint that holds identically, or one whose gradient vanishes at \
         this state (for |q̇|² = v0², the speed v0 must not be zero; for a holonomic h(t, q), ∂h/∂q must not \
         vanish)",
        t = Num(*.t)
    )]
    DegenerateConstraint {
        /// Time.
        t: f64,
        /// The constraint's number, from 1.
        index: usize,
        /// Position.
        q: Vec<f64>,
        /// Velocity.
        qd: Vec<f64>,
    },

    /// The Lagrangian, the constraints or their derivatives gave NaN or infinity.
    #[error(
        "the model evaluated to a non-finite number at t = {t} with q = {q:?}, q̇ = {qd:?} (a square root or \
         logarithm of a negative number, a division by zero, an overflow, or a power at x = 0 exactly: √x, \
         or x.powf(p) with p < 3, whose derivatives dual numbers form as 0·∞ even where they are 0); \
         check the model's domain (start such a power a hair away from 0, as at 1e-100), or, \
         where the state is huge, whether the motion grows without bound (a fixed step beyond the \
         method's stability boundary: halve the step, or use Rodas4)",
        t = Num(*.t)
    )]
    NonFiniteEvaluation {
        /// Time.
        t: f64,
        /// Position.
        q: Vec<f64>,
        /// Velocity.
        qd: Vec<f64>,
    },

    /// The Jacobian of the reduced equations, which the implicit methods take at the start of each
    /// step, is not finite where the equations themselves are: a smaller step cannot help.
    #[error(
        "the Jacobian of the reduced equations is not finite at t = {t} with q = {q:?}, q̇ = {qd:?}, \
         though the equations are (their derivatives overflow, or the model is not differentiable \
         there); an explicit method (Dop853) needs no Jacobian, or state the model in units in which \
         its rates are nearer 1; the motion up to t is kept",
        t = Num(*.t)
    )]
    NonFiniteJacobian {
        /// Time.
        t: f64,
        /// Position.
        q: Vec<f64>,
        /// Velocity.
        qd: Vec<f64>,
    },

    /// The equations became singular along the motion: a constraint's gradient `∂f_a/∂q̇` passed
    /// through zero between two accepted steps, the constraints' gradients became linearly
    /// dependent there, the kinetic metric `W = ∂²L/∂q̇²` changed size by many orders of
    /// magnitude within one step, or a constraint ended at the edge of the model's domain
    /// ([`Singularity::Unbounded`]).
    #[error(
        "singular point at t = {t} (the last state checked, at or after it: q = {q:?}, q̇ = {qd:?}): {} \
         (a rank loss, such as the speed passing through zero under a constraint on its magnitude, \
         or a pole of the model; or a computed state that has drifted off the constraints, which tighter \
         tolerances or Options::project prevent); the equations do not determine the motion there. The motion up to just \
         before t is kept, with its events and output times (an adaptive method steps towards the point, at most halfway at \
         each step; Rk4 keeps its last step before it). Check the model near this state (Problem::equations_at); Options::rank_tolerance sets \
         the threshold",
        match cause {
            Singularity::Gradient(a) => format!("the gradient ∂f/∂q̇ of constraint {a} passes through zero, down to {ratio:e} times its size at the ends of the step"),
            Singularity::DependentGradients => format!("the gradients ∂f/∂q̇ of the constraints become linearly dependent (the frame they span reverses its orientation within one step, each of them leaving that span by at most {ratio:e} of its size)"),
            Singularity::BlockSystem => format!("the block system [W −Jᵀ; J 0] passed through a singular one within one step: its determinant changed sign (the kinetic metric W = ∂²L/∂q̇² on the constraints' tangent space passed through zero; its size changed by a factor {ratio:e})"),
            Singularity::Metric => format!("the kinetic metric ∂²L/∂q̇² changed size by a factor {ratio:e} within one step"),
            Singularity::Unbounded(a) => format!("the gradient of constraint {a} grew without bound after the motion met the edge of the model's domain, and the velocity left the constraint there, missing it by {ratio:.2} of its terms: the constraint ends there, as the curve y = −√(1 − x²) does at x = ±1"),
        },
        t = Num(*.t)
    )]
    SingularPoint {
        /// Time: for a gradient, where it is smallest between the last two states checked (the
        /// ends of consecutive accepted steps), by linear interpolation (exact where the gradient
        /// varies linearly, within the step otherwise); for the metric, the end of the step; for
        /// a constraint that ends, the start of the step (the last state kept).
        t: f64,
        /// What became singular.
        cause: Singularity,
        /// For a gradient, its smallest size on the step over the larger of its sizes at the
        /// step's ends; for dependent gradients, the largest part of one of them (scaled to unit
        /// size) that left the span they had at the start of the step (0 when `J` is square and
        /// its determinant changed sign); for the metric, its size at the end of the step over
        /// that at the start; for a constraint that ends, its relative residual at the end of the
        /// step.
        ratio: f64,
        /// Position at the last state checked, at or after `t`.
        q: Vec<f64>,
        /// Velocity at the last state checked, at or after `t`.
        qd: Vec<f64>,
    },

    /// The step size fell below what floating point can resolve.
    #[error(
        "step size {h:e} too small at t = {t}: the solution changes faster than the tolerance allows there \
         (a singularity of the model or of the motion, such as a collision or a blow-up in finite time; or a \
         stiff problem: {advice}); or t itself is so large that a step this short no longer changes it \
         (steps below 4 ulps of t, {resolution:e} here: count time from a nearer origin)",
        resolution = crate::integrate::time_resolution(*.t), t = Num(*.t)
    )]
    StepSizeTooSmall {
        /// Time.
        t: f64,
        /// The step size.
        h: f64,
        /// What to try, from the method's facts.
        advice: &'static str,
    },

    /// The state left the floating-point range (overflowed to infinity or became NaN).
    #[error(
        "the state is no longer finite after a step from t = {t} (size {h:e}): the motion blows up there, \
         the model leaves its domain, or a fixed step (Rk4) lies beyond the method's stability boundary, \
         so that the motion grows without bound (halve the step, or use Rodas4 for a stiff problem); \
         the motion up to t is kept",
        t = Num(*.t)
    )]
    NonFiniteState {
        /// Time of the last finite state.
        t: f64,
        /// The last step size tried.
        h: f64,
    },

    /// A recorded quantity is not finite.
    #[error(
        "{quantity} is not finite at t = {t} (the model's value leaves its domain there while the motion goes \
         on, or overflows the floating-point range); the motion before t is kept",
        t = Num(*.t)
    )]
    NonFiniteSolution {
        /// Time.
        t: f64,
        /// Which quantity (`q`, `q̇`, `q̈`, `μ`, `Φ`, `f`, `E`, `W_Φ`, `∫∂L/∂t dt`).
        quantity: &'static str,
    },

    /// The step limit was reached.
    #[error("step limit of {max_steps} reached at t = {t}; {hint}", t = Num(*.t))]
    MaxSteps {
        /// Time.
        t: f64,
        /// The limit.
        max_steps: usize,
        /// What to try: raise the limit, or take fewer steps (looser tolerances, or a larger
        /// fixed step for a method without error control); or, where the steps have shrunk to
        /// nothing at one point (`stalled`), look at the model there.
        hint: &'static str,
        /// Whether the steps shrank: the second half of them advanced `t` by less than a
        /// thousandth of what the first half did. At a kink of the model, a singular point or a
        /// blow-up they shrink to nothing and more steps will not pass; a fast but regular phase
        /// after a slow one (the pericentre of an eccentric orbit) looks the same from here.
        stalled: bool,
    },

    /// The explicit method detected stiffness.
    #[error(
        "the problem became stiff at t = {t} (h·|λ| ≈ {h_lambda:.2} at the stability boundary for many steps); \
         use the implicit method {suggestion}",
        t = Num(*.t)
    )]
    Stiff {
        /// Time.
        t: f64,
        /// Estimated `h·|λ|` of the dominant eigenvalue.
        h_lambda: f64,
        /// The method to use instead.
        suggestion: &'static str,
    },

    /// The projection onto `f = 0` did not converge.
    #[error(
        "projection onto the constraints did not converge at t = {t}: residual {residual:e} after {iterations} \
         iterations; tighten the tolerances so that steps stay close to the constraint manifold",
        t = Num(*.t)
    )]
    ProjectionFailed {
        /// Time.
        t: f64,
        /// Residual `max_a |f_a|` after the last iteration.
        residual: f64,
        /// Iterations done.
        iterations: usize,
    },

    /// The projection of the initial state onto the constraints
    /// ([`Problem::with_projected_velocity`](crate::Problem::with_projected_velocity)) did not
    /// converge.
    #[error(
        "the initial state could not be projected onto the constraints at t0 = {t}: residual \
         {residual:e} after {iterations} Newton iterations; there may be no state satisfying them near \
         the one given, or they are singular there (a speed constraint whose prescribed speed is 0 at \
         t0, say): give q and q̇ that satisfy them, or nearly",
        t = Num(*.t)
    )]
    InitialProjectionFailed {
        /// Initial time.
        t: f64,
        /// Residual after the last iteration (relative to the constraints' scale).
        residual: f64,
        /// Iterations done.
        iterations: usize,
    },

    /// An event function returned NaN or infinity.
    #[error(
        "event \"{name}\" (index {index}, numbered from 0 in the order of Options::event) returned \
         {value} at t = {t}: its function left its domain along the motion, and the motion up to \
         t is kept",
        t = Num(*.t), value = Num(*.value)
    )]
    NonFiniteEvent {
        /// The event index, from 0, in the order the events were given.
        index: usize,
        /// The event's name.
        name: String,
        /// Time.
        t: f64,
        /// Its value.
        value: f64,
    },

    /// Sensitivities were asked for but cannot be computed as asked.
    #[error("sensitivities: {what}")]
    Sensitivity {
        /// What is wrong, and what to do.
        what: String,
    },

    /// A seed of the sensitivities moves the initial state off the constraints to first order.
    /// The message names what moves it off (the seed's position, velocity or parameter, the
    /// largest part of the residual) and how to move the rest of the state with it.
    #[error(
        "sensitivity seed \"{seed}\" moves the initial state off {row}{through}: its first-order \
         residual is {residual:e}, {cause}",
        row = Row(*.constraint, *.holonomic),
        through = if *.position { ", in position (h itself)" } else if .holonomic.is_some() { ", through its rate ḣ" } else { "" },
        cause = seed_cause(*.moved_by, *.position, .holonomic.is_some()),
    )]
    InconsistentSeed {
        /// The seed's name.
        seed: String,
        /// The constraint (numbered from 1; holonomic ones after the velocity constraints).
        constraint: usize,
        /// For a holonomic constraint, its number among the holonomic ones (from 1); `None` for
        /// a velocity constraint.
        holonomic: Option<usize>,
        /// Whether the residual is of the holonomic constraint's position, `h_b` itself, rather
        /// than of its rate `ḣ_b` (or of a velocity constraint).
        position: bool,
        /// `δf_a = ∂f_a/∂q δq0 + ∂f_a/∂q̇ δq̇0 + ∂f_a/∂p δp` (for a holonomic constraint, the
        /// same of `ḣ_b`, or, where `position`, `δh_b = ∂h_b/∂q δq0 + ∂h_b/∂p δp`).
        residual: f64,
        /// Which part of the seed makes the largest term of the residual.
        moved_by: SeedPart,
    },
}

/// The part of a sensitivity seed that moves the initial state off a constraint
/// ([`Error::InconsistentSeed`]): the term `∂f/∂q δq0`, `∂f/∂q̇ δq̇0` or `∂f/∂p δp` of its
/// first-order residual that is largest.
#[cfg_attr(feature = "serde", derive(serde::Serialize))]
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[non_exhaustive]
pub enum SeedPart {
    /// The initial positions it moves (`Seed::position`, `Seed::with_position`).
    Position,
    /// The initial velocities it moves (`Seed::velocity`, `Seed::with_velocity`).
    Velocity,
    /// The parameters it moves (`Seed::parameter`, `Seed::with_parameter`).
    Parameter,
}

/// What moves a seed off a constraint and what to do, for [`Error::InconsistentSeed`]: by the part
/// of the seed that does, and the kind of residual (`h` itself, `ḣ` of a holonomic constraint, or a
/// velocity constraint `f`).
fn seed_cause(part: SeedPart, position: bool, holonomic: bool) -> &'static str {
    match (part, position, holonomic) {
        (SeedPart::Position, true, _) => {
            "through the initial position it moves, which leaves h = 0 (∂h/∂q·δq0 ≠ 0): move q0 \
             along the constraint only, with Seed::with_position for the other coordinates (for \
             h = x² + y² − l², a δq0 with x δx + y δy = 0)"
        }
        (SeedPart::Position, false, true) => {
            "through the initial position it moves, which changes ḣ = ∂h/∂q·q̇ + ∂h/∂t at the \
             initial velocity: move q̇0 with it (Seed::with_velocity) so that ḣ stays 0"
        }
        (SeedPart::Position, false, false) => {
            "through the initial position it moves, on which f depends: move q̇0 with it \
             (Seed::with_velocity) so that f stays 0"
        }
        (SeedPart::Velocity, _, true) => {
            "through the initial velocity it moves, which is not along the constraint \
             (∂h/∂q·δq̇0 ≠ 0): move q̇0 only along h = 0, with Seed::with_velocity for the other \
             coordinates (for h = x² + y² − l², a δq̇0 with x δẋ + y δẏ = 0; Seed::velocity(i) \
             alone is along it only where ∂h/∂q_i = 0)"
        }
        (SeedPart::Velocity, _, false) => {
            "through the initial velocity it moves, which leaves f = 0 (∂f/∂q̇·δq̇0 ≠ 0): move q̇0 \
             only in directions that keep f = 0, with Seed::with_velocity for the other components \
             (for f = |q̇|² − v0², a δq̇0 perpendicular to q̇0)"
        }
        (SeedPart::Parameter, true, _) => {
            "through the parameter it moves, which h reads: move q0 with it (for h = x² + y² − l², \
             seed l with the position that keeps h = 0: Seed::parameter(\"l\").with_position(i, \
             dq_i/dl), and the velocity that keeps ḣ = 0)"
        }
        (SeedPart::Parameter, false, true) => {
            "through the parameter it moves, which ḣ reads (a constraint that moves in time: for \
             h = y − x tan ωt, ḣ = ẏ − ẋ tan ωt − ω x sec² ωt): move q̇0 with it, with the \
             velocity that keeps ḣ = 0 (Seed::parameter(\"omega\").with_velocity(i, dq̇_i/dω))"
        }
        (SeedPart::Parameter, false, false) => {
            "through the parameter it moves, which f reads: move q̇0 with it (for f = |q̇|² − v0², \
             seed v0 with the velocity's direction too: Seed::parameter(\"v0\").with_velocity(i, \
             dq̇_i/dv0))"
        }
    }
}

/// What made the equations singular at an [`Error::SingularPoint`].
#[cfg_attr(feature = "serde", derive(serde::Serialize))]
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[non_exhaustive]
pub enum Singularity {
    /// The gradient `∂f_a/∂q̇` of constraint `a` (numbered from 1, velocity constraints first,
    /// then the holonomic ones) passed through zero.
    Gradient(usize),
    /// The gradients of the constraints became linearly dependent, each one staying away from
    /// zero (two constraints whose gradients turn parallel; for as many constraints as
    /// coordinates, `det ∂f/∂q̇` changing sign).
    DependentGradients,
    /// The kinetic metric `W = ∂²L/∂q̇²` changed size by many orders of magnitude within a step.
    Metric,
    /// The block matrix `[W −Jᵀ; J 0]` passed through a singular one within a step: the sign of
    /// its determinant changed (`W` on the constraints' tangent space passing through zero, as
    /// `W = 1 − t` at `t = 1`), however little `W` changed in size.
    BlockSystem,
    /// The gradient of constraint `a` (numbered as for [`Singularity::Gradient`]) grew without
    /// bound after the motion met the edge of the model's domain, and the velocity left the
    /// constraint there: the constraint ends (the curve `y = √(1 − x)` at `x = 1`, whose tangent
    /// turns across the motion). `ratio` is the relative residual `|f_a|/(Σ_i |J_ai q̇_i| + |f_a|)`.
    Unbounded(usize),
}

/// A constraint row in a message: `Row(index, holonomic)` with `index` numbered from 1 over the
/// velocity constraints and then the holonomic ones, and `holonomic` the number among the
/// holonomic ones when the row is one.
struct Row(usize, Option<usize>);

impl std::fmt::Display for Row {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self.1 {
            None => write!(f, "velocity constraint {} (numbered from 1)", self.0),
            Some(b) => write!(
                f,
                "holonomic constraint {b} (numbered from 1 among the holonomic ones)"
            ),
        }
    }
}

/// A list of constraint numbers in a message: `1`, `1 and 2`, `1, 2 and 3`.
struct Numbers<'a>(&'a [usize]);

impl std::fmt::Display for Numbers<'_> {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        let mut sorted = self.0.to_vec();
        sorted.sort_unstable();
        for (i, b) in sorted.iter().enumerate() {
            if i > 0 {
                write!(f, "{}", if i + 1 == sorted.len() { " and " } else { ", " })?;
            }
            write!(f, "{b}")?;
        }
        Ok(())
    }
}

/// A number in a message: as written for moderate magnitudes, in scientific notation for tiny
/// and huge ones (so `1e-300` is not printed with three hundred zeros).
struct Num(f64);

impl std::fmt::Display for Num {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        let x = self.0;
        if x != 0.0 && x.is_finite() && !(1e-5..1e16).contains(&x.abs()) {
            write!(f, "{x:e}")
        } else {
            write!(f, "{x}")
        }
    }
}

impl std::fmt::Debug for Error {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        std::fmt::Display::fmt(self, f)
    }
}
