//! The equations shown: the structure probed for a model whose blocks depend on different things,
//! and the report.

use chetaev::prelude::*;

use crate::common::Paper;

/// `L = ½ (1 + x²) ẋ² + ½ ẏ² + t ẋ − y sin t` with `f = ẋ ẏ − x`: `W` depends on `x` only,
/// `g = (2 x ẋ², 0) + (1, 0)` on `q` and `q̇`, `∂L/∂t = ẋ − y cos t` on all three, `J = (ẏ, ẋ)` on
/// `q̇` only, `c = −ẋ` on `q̇`.
struct Mixed;

impl Lagrangian<2> for Mixed {
    fn lagrangian<R: Real>(&self, t: R, q: &SVector<R, 2>, qd: &SVector<R, 2>) -> R {
        (q[0] * q[0] + 1.0) * qd[0] * qd[0] * 0.5 + qd[1] * qd[1] * 0.5 + t * qd[0] - q[1] * t.sin()
    }
}

impl Constraints<2, 1> for Mixed {
    fn constraints<R: Real>(&self, _t: R, q: &SVector<R, 2>, qd: &SVector<R, 2>) -> SVector<R, 1> {
        SVector::from([qd[0] * qd[1] - q[0]])
    }
}

#[test]
fn the_structure_of_each_block_is_found_and_reported() -> Result<(), Error> {
    let problem = Problem::new(
        Mixed,
        0.5,
        SVector::from([1.0, 0.5]),
        SVector::from([0.5, 2.0]),
    )?;
    let d = problem.describe(0.5, &[1.0, 0.5], &[0.5, 2.0])?;
    let s = &d.structure;
    assert_eq!(s.sizes, (2, 1));
    assert!(s.w.q && !s.w.t && !s.w.qd, "W {:?}", s.w);
    assert_eq!(s.w_pattern, vec![true, false, false, true]);
    assert!(s.g.q && s.g.qd && !s.g.zero, "g {:?}", s.g);
    assert!(s.dl_dt.t && s.dl_dt.q && s.dl_dt.qd, "∂L/∂t {:?}", s.dl_dt);
    assert!(s.j.qd && !s.j.q && !s.j.t, "J {:?}", s.j);
    assert!(s.c.qd && !s.c.q && !s.c.t, "c {:?}", s.c);
    assert!(s.forces.zero);
    // The numbers at the state agree with the equations at the state.
    let eq = problem.equations_at(0.5, &[1.0, 0.5], &[0.5, 2.0])?;
    assert_eq!(d.dynamics.qdd, eq.qdd);
    assert_eq!(d.lagrangian.w, vec![2.0, 0.0, 0.0, 1.0]);
    // No row reaches y (∂L/∂y = −sin t, and y is nowhere else); x, ẋ, ẏ and t each reach both
    // rows of q̈: four passes for five columns.
    assert_eq!(d.jacobian_passes, Some((4, 5)));
    let text = d.to_string();
    for needle in [
        "W = ∂²L/∂q̇²",
        "depends on q",
        "J = ∂f/∂q̇",
        "pattern ×· / ·×",
        "pivot",
        "4 forward passes for its 5 columns",
    ] {
        assert!(text.contains(needle), "{needle} not in\n{text}");
    }
    Ok(())
}

#[test]
fn a_negative_zero_is_reported_as_zero() -> Result<(), Error> {
    let (q0, qd0) = ([0.0, 5.0], [10.0, 0.0]);
    // The paper's model at its start, where `μ(0) = −(m g / 2 v0)·tanh 0` comes out as a negative
    // zero: the report prints `0`, not `-0`.
    let problem = Problem::new(
        Paper { v0: 10.0 },
        0.0,
        SVector::from(q0),
        SVector::from(qd0),
    )?;
    let d = problem.describe(0.0, &q0, &qd0)?;
    assert_eq!(d.dynamics.mu[0], 0.0);
    let text = d.to_string();
    assert!(!text.contains("-0"), "{text}");
    assert!(text.contains("μ     = [0]"), "{text}");
    Ok(())
}
