//! Many coordinates: the derivatives must not exhaust a thread's stack (2 MiB for a test thread).

use chetaev::prelude::*;

/// N coupled oscillators with a constraint on the total speed.
struct Free;
impl<const N: usize> Lagrangian<N> for Free {
    fn lagrangian<R: Real>(&self, _t: R, q: &SVector<R, N>, qd: &SVector<R, N>) -> R {
        let mut l = qd.dot(qd) * 0.5 - q.dot(q) * 0.5;
        for i in 1..N {
            l -= (q[i] - q[i - 1]).powi(2) * 0.1;
        }
        l
    }
}
impl<const N: usize> Constraints<N, 1> for Free {
    fn constraints<R: Real>(&self, _t: R, _q: &SVector<R, N>, qd: &SVector<R, N>) -> SVector<R, 1> {
        SVector::from([qd.dot(qd) - 1.0])
    }
}

fn run<const N: usize, Me: Method + Copy>(method: Me) {
    let mut qd0 = SVector::<f64, N>::zeros();
    qd0[0] = 1.0;
    let q0 = SVector::<f64, N>::from_fn(|i, _| 0.01 * i as f64);
    let p = Problem::new(Free, 0.0, q0, qd0).expect("valid");
    let projection = Projection::default();
    let options = Options::until(0.5)
        .tolerances(1e-8, 1e-8)
        .project(projection);
    let sol = solve(&p, method, &options).expect("valid options");
    assert!(sol.is_success(), "N = {N}: {:?}", sol.status);
    // The projection's bound: |f| ≤ tol·|J|·|q̇| = tol · 2|q̇|² = 2 tol.
    assert!(
        sol.max_residual().expect("recorded") <= 2.0 * projection.tol,
        "N = {N}: {:e}",
        sol.max_residual().expect("recorded")
    );
    // E = ½|q̇|² + V changes only by the work of Φ; the balance is a quadrature of the motion,
    // accurate to about the tolerance asked for times the energy scale (here of order 1).
    let worst = sol
        .energy_balance()
        .iter()
        .fold(0.0f64, |a, b| a.max(b.abs()));
    assert!(worst <= 1e-6, "N = {N}: energy balance {worst:e}");
}

#[test]
fn forty_coordinates_explicit() {
    run::<40, _>(Dop853::default());
}

#[test]
fn sixty_four_coordinates_explicit() {
    run::<64, _>(Dopri5::default());
}

#[test]
fn thirty_coordinates_implicit() {
    // Rodas4 differentiates the whole right-hand side once more: nested dual numbers, twice the size.
    run::<30, _>(Rodas4);
}

#[test]
fn column_hessian_and_dense_hessian_are_both_exact() {
    // N = 9 takes W by columns, N = 8 in one pass.
    use chetaev::equations::derivatives::velocity_hessian;
    let q9 = SVector::<f64, 9>::from_fn(|i, _| 0.1 * i as f64 - 0.3);
    let qd9 = SVector::<f64, 9>::from_fn(|i, _| 0.2 * i as f64 + 0.1);
    let (l9, p9, w9) = velocity_hessian(&Coupled, 0.4, &q9, &qd9);
    let q8 = SVector::<f64, 8>::from_fn(|i, _| q9[i]);
    let qd8 = SVector::<f64, 8>::from_fn(|i, _| qd9[i]);
    let (_, p8, w8) = velocity_hessian(&Coupled, 0.4, &q8, &qd8);
    assert!(l9.is_finite());
    // Both against the hand-derived W (and p = W q̇, L being quadratic in q̇).
    for i in 0..9 {
        for j in 0..9 {
            let expected = if i == j {
                1.0 + q9[i] * q9[i]
            } else {
                0.05 * (q9[i] + q9[j])
            };
            assert!(
                (w9[(i, j)] - expected).abs() <= 1e-14,
                "W[{i},{j}] = {} vs {expected}",
                w9[(i, j)]
            );
            if i < 8 && j < 8 {
                assert!(
                    (w8[(i, j)]
                        - (if i == j {
                            1.0 + q8[i] * q8[i]
                        } else {
                            0.05 * (q8[i] + q8[j])
                        }))
                    .abs()
                        <= 1e-14
                );
            }
        }
        let pi: f64 = (0..9).map(|j| w9[(i, j)] * qd9[j]).sum();
        assert!((p9[i] - pi).abs() <= 1e-13);
    }
    assert!((p8[0] - (0..8).map(|j| w8[(0, j)] * qd8[j]).sum::<f64>()).abs() <= 1e-13);
}

/// L = ½ q̇ᵀ W(q) q̇ with W_ii = 1 + q_i², W_ij = 0.05 (q_i + q_j): a configuration-dependent,
/// fully coupled mass matrix.
struct Coupled;
impl<const N: usize> Lagrangian<N> for Coupled {
    fn lagrangian<R: Real>(&self, _t: R, q: &SVector<R, N>, qd: &SVector<R, N>) -> R {
        let mut l = R::zero();
        for i in 0..N {
            for j in 0..N {
                let w = if i == j {
                    q[i] * q[i] + 1.0
                } else {
                    (q[i] + q[j]) * 0.05
                };
                l += w * qd[i] * qd[j] * 0.5;
            }
        }
        l
    }
}
