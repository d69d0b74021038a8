//! Event location: roots of user functions `g(t, q, q̇)` found on the dense output.

use std::sync::Arc;

use super::options::EventFn;
use crate::model::Real;
use crate::sensitivity::{event_gradient, EventGradient};

/// An event function written once for any scalar, like the model's functions, so that its
/// gradient is exact: what sensitivities of event times and states need
/// ([`Event::smooth`]). It may read parameters with [`Real::parameter`].
///
/// ```
/// use chetaev::prelude::*;
/// struct Ground;
/// impl EventFunction for Ground {
///     fn value<R: Real>(&self, _t: R, q: &[R], _qd: &[R]) -> R {
///         q[1]
///     }
/// }
/// let impact = Event::smooth("impact", Ground).falling().terminal();
/// ```
pub trait EventFunction: Send + Sync + 'static {
    /// `g(t, q, q̇)`.
    fn value<R: Real>(&self, t: R, q: &[R], qd: &[R]) -> R;
}

/// The gradient of an event function at a point, with respect to `t`, `q`, `q̇` and the
/// parameters it reads; `None` where it cannot be taken exactly.
pub(crate) type EventGradientFn =
    Arc<dyn Fn(f64, &[f64], &[f64]) -> Option<EventGradient> + Send + Sync>;

/// Which sign changes of `g` count.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Direction {
    /// Both.
    Either,
    /// `g` going from negative to positive (in the direction of integration).
    Rising,
    /// `g` going from positive to negative (in the direction of integration).
    Falling,
}

/// An event: a function `g(t, q, q̇)` whose zeros are located, a direction, and whether it stops
/// the integration.
///
/// A run never ends at its start time because of an event. A function zero at the start time
/// (exactly, or within the rounding of the initial state: a `q̇0` computed as `v0 sin π`) is not
/// armed there: leaving zero is not a crossing, in whichever direction it leaves, so no event is
/// reported at the start. The event is armed once the function has left zero, and from then on its
/// crossings count as usual, from the sign it has taken. The solution says so with a
/// [`Warning::EventZeroAtStart`](crate::Warning::EventZeroAtStart).
///
/// So the apex `ẏ` falling of a horizontal launch (`ẏ0 = 0`, and `ẏ < 0` at once) is not
/// reported at `t0`, nor ever after unless `ẏ` becomes positive and falls again; the landing
/// `y` falling of a launch upward from the ground (`y0 = 0`) is the landing, not the start; and
/// `x = sin t` rising is first reported at `2π`, not at `0`.
///
/// A function that touches zero and keeps its sign (`g = (t − a)²`) does not cross, also where a
/// sample or the search between samples lands on the zero exactly; only a zero exactly at the end
/// of a step, whose next sign is not known yet, counts as a crossing from the side it came from.
#[derive(Clone)]
pub struct Event {
    /// A name for reports.
    pub name: String,
    /// The event function.
    pub g: EventFn,
    /// Which crossings count.
    pub direction: Direction,
    /// Whether the integration stops at the first crossing.
    pub terminal: bool,
    /// The exact gradient of `g`, for an event made by [`Event::smooth`].
    pub(crate) gradient: Option<EventGradientFn>,
}

impl std::fmt::Debug for Event {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Event")
            .field("name", &self.name)
            .field("direction", &self.direction)
            .field("terminal", &self.terminal)
            .field("smooth", &self.gradient.is_some())
            .finish_non_exhaustive()
    }
}

impl Event {
    /// An event with function `g`, counting crossings in both directions, not terminal.
    pub fn new(
        name: impl Into<String>,
        g: impl Fn(f64, &[f64], &[f64]) -> f64 + Send + Sync + 'static,
    ) -> Self {
        Self {
            name: name.into(),
            g: Arc::new(g),
            direction: Direction::Either,
            terminal: false,
            gradient: None,
        }
    }

    /// An event with a function written for any scalar ([`EventFunction`]): the same as
    /// [`Event::new`] for locating it, and its exact gradient gives the sensitivities of the event's
    /// time and state ([`Sensitivities::events`](crate::Sensitivities::events)).
    pub fn smooth(name: impl Into<String>, g: impl EventFunction) -> Self {
        let g = Arc::new(g);
        let value = Arc::clone(&g);
        Self {
            gradient: Some(Arc::new(move |t, q, qd| event_gradient(&*g, t, q, qd))),
            ..Self::new(name, move |t, q, qd| value.value(t, q, qd))
        }
    }

    /// Counts only crossings from positive to negative.
    pub fn falling(mut self) -> Self {
        self.direction = Direction::Falling;
        self
    }

    /// Counts only crossings from negative to positive.
    pub fn rising(mut self) -> Self {
        self.direction = Direction::Rising;
        self
    }

    /// Stops the integration at the first crossing.
    pub fn terminal(mut self) -> Self {
        self.terminal = true;
        self
    }
}

/// Whether going from `g0` to `g1` (in the direction of integration) is a crossing in `direction`.
pub(crate) fn crosses(direction: Direction, g0: f64, g1: f64) -> bool {
    if g0 == 0.0 {
        return false;
    }
    let rising = g0 < 0.0 && g1 >= 0.0;
    let falling = g0 > 0.0 && g1 <= 0.0;
    match direction {
        Direction::Either => rising || falling,
        Direction::Rising => rising,
        Direction::Falling => falling,
    }
}

/// A located event.
#[cfg_attr(feature = "serde", derive(serde::Serialize))]
#[derive(Clone, Debug, PartialEq)]
pub struct EventHit {
    /// Index of the event in the options.
    pub index: usize,
    /// The time of the zero of `g`.
    pub t: f64,
    /// Position at that time.
    pub q: Vec<f64>,
    /// Velocity at that time.
    pub qd: Vec<f64>,
}

/// The position of `x` in the order of the finite `f64`s: consecutive numbers differ by 1, and
/// `-0.0` and `+0.0` are both 0.
fn ordinal(x: f64) -> i64 {
    let magnitude = (x.abs().to_bits() & !(1u64 << 63)) as i64;
    if x < 0.0 {
        -magnitude
    } else {
        magnitude
    }
}

/// The number halfway between `a` and `b` in the order of the `f64`s ([`ordinal`]): a bisection
/// by it finds any `f64` in at most 64 halvings, however many orders of magnitude apart `a` and
/// `b` are (a root at `1e-151` in a step `[0, 4e-7]`).
fn ordinal_midpoint(a: f64, b: f64) -> f64 {
    let mid = (i128::from(ordinal(a)) + i128::from(ordinal(b))).div_euclid(2);
    let magnitude = f64::from_bits(mid.unsigned_abs() as u64);
    if mid < 0 {
        -magnitude
    } else {
        magnitude
    }
}

/// Finds a root of `g` in `[a, b]` (either order) given `g(a) = ga`, `g(b) = gb` of opposite signs
/// (or `gb = 0`), by the Illinois variant of regula falsi, to within a few ulps of `t`. Where three
/// steps of it have not halved the bracket, counted in `f64`s between its ends, and the values at
/// its ends differ by more than 1e12 times, the next is a bisection, alternately by
/// [`ordinal_midpoint`] and in value, so a root many orders of magnitude from the bracket's size
/// is found in a bounded number of evaluations; an ordinary root costs what regula falsi costs.
/// Returns the root and the number of evaluations.
pub(crate) fn locate_root(
    mut g: impl FnMut(f64) -> f64,
    mut a: f64,
    mut ga: f64,
    mut b: f64,
    mut gb: f64,
) -> (f64, usize) {
    let mut evals = 0;
    if gb == 0.0 {
        return (b, evals);
    }
    let mut side = 0i8;
    let span = |a: f64, b: f64| (i128::from(ordinal(a)) - i128::from(ordinal(b))).unsigned_abs();
    // The bracket's span when last halved, and the steps since.
    let (mut mark, mut since, mut forced) = (span(a, b), 0, 0u32);
    for _ in 0..200 {
        let tol = 4.0 * f64::EPSILON * a.abs().max(b.abs()).max(f64::MIN_POSITIVE);
        if (b - a).abs() <= tol {
            break;
        }
        let width = span(a, b);
        if width <= mark / 2 {
            (mark, since) = (width, 0);
        }
        let mut c = (a * gb - b * ga) / (gb - ga);
        // Keep c strictly inside; bisect where the secant leaves the bracket or has stalled.
        let (lo, hi) = if a < b { (a, b) } else { (b, a) };
        // Stalled with ends of values so far apart that a secant step barely moves (|g| of 0.1
        // against 1e287): regula falsi would need a halving of the weight per factor of 2.
        let lopsided = (ga / gb).abs().max((gb / ga).abs()) > 1e12;
        if since >= 3 && lopsided {
            // Alternately in the order of the floats (a root many orders of magnitude inside)
            // and in value (a root of ordinary size, where the secant crept from one end).
            c = if forced % 2 == 0 {
                ordinal_midpoint(a, b)
            } else {
                0.5 * (a + b)
            };
            forced += 1;
            since = 0;
            mark = width;
        } else if !(c > lo && c < hi) {
            c = 0.5 * (a + b);
        }
        if !(c > lo && c < hi) {
            break;
        }
        since += 1;
        let gc = g(c);
        evals += 1;
        if gc == 0.0 || !gc.is_finite() {
            return (c, evals);
        }
        if (gc > 0.0) == (gb > 0.0) {
            b = c;
            gb = gc;
            if side == -1 {
                ga *= 0.5;
            }
            side = -1;
        } else {
            a = c;
            ga = gc;
            if side == 1 {
                gb *= 0.5;
            }
            side = 1;
        }
    }
    // The endpoint on the far side of the crossing, so the event lies inside the interval stepped.
    (b, evals)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn finds_a_root_to_a_few_ulps() {
        let f = |x: f64| x.cos() - x;
        let (r, n) = locate_root(f, 0.0, f(0.0), 1.0, f(1.0));
        assert!(
            (r - 0.739_085_133_215_160_6).abs() <= 4.0 * f64::EPSILON,
            "{r}"
        );
        assert!(n < 20, "{n}");
    }

    #[test]
    fn finds_a_root_far_smaller_than_its_bracket() {
        // y = h − g t²/2 with h = 0.1, g = 1e300: the root 4.47e-151 in [0, 4e-7], where g(b) is
        // 1e288 times g(a) and regula falsi alone creeps from b.
        let g = |t: f64| 0.1 - 0.5e300 * t * t;
        let root = (2.0 * 0.1 / 1e300f64).sqrt();
        let (r, n) = locate_root(g, 0.0, g(0.0), 4e-7, g(4e-7));
        assert!(
            (r - root).abs() <= 8.0 * f64::EPSILON * root,
            "{r} against {root}"
        );
        assert!(n < 200, "{n}");
        // And backward, the bracket given from its far end.
        let (r, n) = locate_root(g, 4e-7, g(4e-7), 0.0, g(0.0));
        assert!(
            (r - root).abs() <= 8.0 * f64::EPSILON * root,
            "{r} against {root}"
        );
        assert!(n < 200, "{n}");
    }

    #[test]
    fn an_ordinary_root_costs_what_regula_falsi_costs() {
        // A root where the secant creeps from one end: the forced bisections must not send the
        // search to the tiny floats near 0 over and over.
        for shift in [0.0, 100.0] {
            let g = |t: f64| (t - shift - 0.7).powi(3) + 0.1 * (t - shift - 0.7);
            let (a, b) = (shift, shift + 1.0);
            let (r, n) = locate_root(g, a, g(a), b, g(b));
            assert!(
                (r - shift - 0.7).abs() <= 8.0 * f64::EPSILON * (shift + 1.0),
                "{r}"
            );
            assert!(n <= 25, "{n} evaluations from {a}");
        }
    }

    #[test]
    fn the_midpoint_in_the_order_of_the_floats() {
        assert_eq!(ordinal_midpoint(1.0, 1.0), 1.0);
        assert_eq!(ordinal(-0.0), ordinal(0.0));
        let m = ordinal_midpoint(0.0, 4e-7);
        assert!(m > 1e-170 && m < 1e-150, "{m}");
        assert_eq!(ordinal_midpoint(-2.0, 2.0), 0.0);
        assert!(ordinal_midpoint(1.0, 2.0) > 1.0 && ordinal_midpoint(1.0, 2.0) < 2.0);
    }

    #[test]
    fn direction_filters_crossings() {
        let e = Event::new("x", |_, q, _| q[0]).falling();
        assert!(crosses(e.direction, 1.0, -1.0));
        assert!(!crosses(e.direction, -1.0, 1.0));
        assert!(!crosses(e.direction, 0.0, -1.0));
        let e = Event::new("x", |_, q, _| q[0]).rising();
        assert!(crosses(e.direction, -1.0, 0.0));
    }
}
