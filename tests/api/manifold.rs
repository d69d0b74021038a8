//! The constraint manifold: dependent coordinates and speeds completed by Newton's method, and the
//! reduced equations linearised on the manifold, against closed forms.

use chetaev::manifold::{complete, Independent};
use chetaev::prelude::*;

/// The paper's particle: `L = ½|q̇|² − g y`, `f = |q̇|² − v0²` (nonlinear in the speeds).
struct Uniform {
    g: f64,
    v0: f64,
}

impl DynModel for Uniform {
    fn sizes(&self) -> (usize, usize) {
        (2, 1)
    }
    fn lagrangian<R: Real>(&self, _t: R, q: &[R], qd: &[R]) -> R {
        (qd[0] * qd[0] + qd[1] * qd[1]) * 0.5 - q[1] * self.g
    }
    fn constraints<R: Real>(&self, _t: R, _q: &[R], qd: &[R], f: &mut [R]) {
        f[0] = qd[0] * qd[0] + qd[1] * qd[1] - self.v0 * self.v0;
    }
}

const PAPER: Uniform = Uniform { g: 10.0, v0: 10.0 };

#[test]
fn a_dependent_speed_of_a_nonlinear_constraint_is_the_root_nearest_its_guess() -> Result<(), Error>
{
    let only_x = Independent::new(vec![0, 1], vec![0]);
    // ẋ = 6 held, ẏ from ẋ² + ẏ² = 100: −8 from a guess 10 % off below, +8 from one above.
    let down = complete(&PAPER, 0.0, &[0.0, 5.0], &[6.0, -7.2], &only_x)?;
    assert_eq!(down.qd[0], 6.0);
    assert!((down.qd[1] + 8.0).abs() < 1e-14, "{:?}", down.qd);
    let up = complete(&PAPER, 0.0, &[0.0, 5.0], &[6.0, 8.8], &only_x)?;
    assert!((up.qd[1] - 8.0).abs() < 1e-14, "{:?}", up.qd);
    // Newton's method converges quadratically: from 10 % off, a handful of iterations.
    assert!(down.iterations.1 <= 10 && up.iterations.1 <= 10, "{down:?}");
    assert_eq!(down.dependent_speeds, vec![1]);
    assert!(down.dependent_coordinates.is_empty() && down.iterations.0 == 0);
    Ok(())
}

#[test]
fn the_dependent_speed_is_chosen_by_the_largest_pivot_where_none_is_named() -> Result<(), Error> {
    // J = 2 (ẋ, ẏ) = (12, −14.4): ẏ has the larger entry, so ẏ is dependent.
    let done = complete(
        &PAPER,
        0.0,
        &[0.0, 5.0],
        &[6.0, -7.2],
        &Independent::automatic(),
    )?;
    assert_eq!(done.dependent_speeds, vec![1]);
    assert!((done.qd[1] + 8.0).abs() < 1e-14);
    Ok(())
}

#[test]
fn a_speed_the_constraint_cannot_reach_is_a_typed_error_naming_the_constraint() {
    // ẋ = 12 > v0: no ẏ satisfies ẋ² + ẏ² = 100.
    let e = complete(
        &PAPER,
        0.0,
        &[0.0, 5.0],
        &[12.0, -1.0],
        &Independent::new(vec![0, 1], vec![0]),
    )
    .expect_err("no solution");
    match &e {
        Error::Completion {
            stage,
            constraint,
            holonomic,
            ..
        } => {
            assert_eq!((*stage, *constraint, *holonomic), ("speeds", 1, None));
        }
        other => panic!("{other}"),
    }
    let text = e.to_string();
    assert!(text.contains("velocity constraint 1"), "{text}");
}

#[test]
fn a_dependent_speed_the_constraint_does_not_determine_is_refused_with_advice() {
    // At the guess ẏ = 0 the constraint's gradient in ẏ vanishes: Newton's method cannot move ẏ.
    // (A state that already satisfies the constraints is returned as it is, whatever its block.)
    let e = complete(
        &PAPER,
        0.0,
        &[0.0, 5.0],
        &[6.0, 0.0],
        &Independent::new(vec![0, 1], vec![0]),
    )
    .expect_err("singular");
    let text = e.to_string();
    assert!(text.contains("do not determine"), "{text}");
    assert!(text.contains("choose other independent speeds"), "{text}");
}

#[test]
fn independent_indices_are_checked_before_anything_is_solved() {
    let bad = [
        (Independent::new(vec![0, 1], vec![0, 1]), "have 1"),
        (Independent::new(vec![0, 1], vec![2]), "out of range"),
        (Independent::new(vec![0, 0], vec![0]), "given twice"),
    ];
    for (ind, says) in bad {
        let e = complete(&PAPER, 0.0, &[0.0, 5.0], &[6.0, -8.0], &ind).expect_err("bad indices");
        assert!(
            matches!(e, Error::InvalidModel { .. }) && e.to_string().contains(says),
            "{e}"
        );
    }
    let e = complete(
        &PAPER,
        0.0,
        &[0.0, f64::NAN],
        &[6.0, -8.0],
        &Independent::automatic(),
    )
    .expect_err("NaN");
    assert!(matches!(e, Error::NonFiniteInput { .. }), "{e}");
}

/// A pendulum of length `l` in Cartesian coordinates: `h = x² + y² − l²`.
struct Pendulum {
    g: f64,
    l: f64,
}

impl DynModel for Pendulum {
    fn sizes(&self) -> (usize, usize) {
        (2, 0)
    }
    fn lagrangian<R: Real>(&self, _t: R, q: &[R], qd: &[R]) -> R {
        (qd[0] * qd[0] + qd[1] * qd[1]) * 0.5 - q[1] * self.g
    }
    fn holonomic_count(&self) -> usize {
        1
    }
    fn holonomic<R: Real>(&self, _t: R, q: &[R], h: &mut [R]) {
        h[0] = q[0] * q[0] + q[1] * q[1] - self.l * self.l;
    }
}

#[test]
fn a_dependent_coordinate_and_its_speed_are_solved_on_a_holonomic_constraint() -> Result<(), Error>
{
    let p = Pendulum { g: 9.81, l: 2.0 };
    // x = 1.2 held: y = −√(4 − 1.44) = −1.6 from a guess 10 % off; ẋ = 0.8: ẏ = −x ẋ / y = 0.6.
    let done = complete(
        &p,
        0.0,
        &[1.2, -1.76],
        &[0.8, 0.0],
        &Independent::new(vec![0], vec![0]),
    )?;
    assert!((done.q[1] + 1.6).abs() < 1e-14, "{:?}", done.q);
    assert!((done.qd[1] - 0.6).abs() < 1e-14, "{:?}", done.qd);
    assert!(done.iterations.0 <= 10);
    // The completed state is accepted as consistent.
    Problem::dynamic(p, 0.0, done.q, done.qd)?;
    Ok(())
}

#[test]
fn the_pendulum_linearised_hanging_oscillates_and_inverted_diverges_at_sqrt_g_over_l(
) -> Result<(), Error> {
    let (g, l): (f64, f64) = (9.81, 2.0);
    let rate = (g / l).sqrt();
    let ind = Independent::new(vec![0], vec![0]);
    let hanging = Problem::dynamic(Pendulum { g, l }, 0.0, vec![0.0, -l], vec![0.0, 0.0])?;
    let lin = hanging.linearize(0.0, &[0.0, -l], &[0.0, 0.0], &ind)?;
    assert_eq!(lin.dim(), 2);
    assert_eq!(
        (lin.coordinates.clone(), lin.speeds.clone()),
        (vec![0], vec![0])
    );
    // Eigenvalues ±i√(g/l), to rounding of the exact Jacobian.
    assert!(lin.eigenvalues[0].re.abs() < 1e-12 && (lin.eigenvalues[0].im + rate).abs() < 1e-12);
    assert!(lin.eigenvalues[1].re.abs() < 1e-12 && (lin.eigenvalues[1].im - rate).abs() < 1e-12);
    let inverted = Problem::dynamic(Pendulum { g, l }, 0.0, vec![0.0, l], vec![0.0, 0.0])?;
    let lin = inverted.linearize(0.0, &[0.0, l], &[0.0, 0.0], &ind)?;
    assert!((lin.eigenvalues[0].re + rate).abs() < 1e-12 && lin.eigenvalues[0].im.abs() < 1e-12);
    assert!((lin.eigenvalues[1].re - rate).abs() < 1e-12);
    // Each eigenvector v satisfies A v = λ v.
    for (lambda, v) in lin.eigenvalues.iter().zip(&lin.eigenvectors) {
        let p = lin.dim();
        for i in 0..p {
            let av: nalgebra::Complex<f64> = (0..p).map(|j| v[j] * lin.a[i * p + j]).sum();
            assert!(
                (av - lambda * v[i]).norm() < 1e-12,
                "{av} vs {}",
                lambda * v[i]
            );
        }
    }
    Ok(())
}

/// The Chaplygin sleigh: a body of mass `m` and inertia `I` about its centre `(x, y)`, heading
/// `θ`, on a knife edge at `a` along its axis that cannot slide sideways:
/// `−ẋ sin θ + ẏ cos θ + a θ̇ = 0`.
struct Sleigh {
    m: f64,
    i: f64,
    a: f64,
}

impl DynModel for Sleigh {
    fn sizes(&self) -> (usize, usize) {
        (3, 1)
    }
    fn lagrangian<R: Real>(&self, _t: R, _q: &[R], qd: &[R]) -> R {
        (qd[0] * qd[0] + qd[1] * qd[1]) * (0.5 * self.m) + qd[2] * qd[2] * (0.5 * self.i)
    }
    fn constraints<R: Real>(&self, _t: R, q: &[R], qd: &[R], f: &mut [R]) {
        f[0] = -qd[0] * q[2].sin() + qd[1] * q[2].cos() + qd[2] * self.a;
    }
}

#[test]
fn the_sleigh_running_straight_relaxes_at_m_a_u_over_i_plus_m_a_squared_and_its_position_is_cyclic(
) -> Result<(), Error> {
    // Body frame: (I + m a²) ω̇ = m a u ω, so about straight running at speed u the turning rate
    // relaxes at m a u / (I + m a²): stable with the edge behind the centre (a < 0).
    let s = Sleigh {
        m: 2.0,
        i: 0.3,
        a: -0.5,
    };
    let u = 1.5;
    let expected = s.m * s.a * u / (s.i + s.m * s.a * s.a);
    let (q, qd) = (vec![0.0, 0.0, 0.0], vec![u, 0.0, 0.0]);
    let problem = Problem::dynamic(s, 0.0, q.clone(), qd.clone())?;
    let lin = problem.linearize(0.0, &q, &qd, &Independent::new(vec![0, 1, 2], vec![0, 2]))?;
    assert_eq!(lin.dim(), 5);
    // x and y appear nowhere: cyclic, each a zero column and a zero eigenvalue.
    assert_eq!(lin.cyclic, vec![0, 1]);
    let nonzero: Vec<_> = lin
        .eigenvalues
        .iter()
        .filter(|l| l.norm() > 1e-12)
        .collect();
    assert_eq!(nonzero.len(), 1, "{:?}", lin.eigenvalues);
    assert!(
        (nonzero[0].re - expected).abs() < 1e-12 * expected.abs(),
        "{nonzero:?} vs {expected}"
    );
    assert!(nonzero[0].im.abs() < 1e-12);
    Ok(())
}
