//! The verification report: Table 42.1 rebuilt, observed orders, and the JSON shape the binary
//! promises.

use uniform_projectile::closed_form::Params;
use uniform_projectile::report::build;

#[test]
fn report_rebuilds_table_42_1_and_observes_the_orders() {
    let tol = 1e-12;
    let r = build(&Params::PAPER, tol).expect("report");
    for row in [&r.table.classical, &r.table.uniform] {
        let e = &row.rel_error;
        // The table quantities are measured at the impact, located to rounding; the length by
        // quadrature on the dense output. 100·tol is a margin of about 10 over what is observed.
        for v in [e.t, e.r, e.v_r, e.impact_angle_deg, e.s] {
            assert!(v <= 100.0 * tol, "{e:?}");
        }
    }
    // The uniform motion lands closer, later, on a shorter path (the paper's conclusion).
    let (c, u) = (&r.table.classical.closed_form, &r.table.uniform.closed_form);
    assert!(u.r < c.r && u.t > c.t && u.s < c.s);

    for c in &r.convergence {
        // SciML's convention: observed order within ±0.3 of the theoretical one.
        assert!(
            (c.order - c.expected).abs() <= 0.3,
            "{} vs {}: {:.2} (expected {})",
            c.method,
            c.against,
            c.order,
            c.expected
        );
    }
    let ue = &r.uniform_errors;
    for v in [
        ue.x,
        ue.y,
        ue.xd,
        ue.yd,
        ue.xdd,
        ue.ydd,
        ue.curvature,
        ue.energy_balance,
    ] {
        assert!(v <= 100.0 * tol, "{ue:?}");
    }
    assert!(ue.mu.unwrap_or(1.0) <= 100.0 * tol && ue.phi.unwrap_or(1.0) <= 100.0 * tol);
    assert!(ue.work_vs_potential.unwrap_or(1.0) <= 100.0 * tol);
    assert!(r
        .work_precision
        .iter()
        .all(|w| w.error.is_finite() && w.seconds > 0.0 && w.rhs_evaluations > 0));
}

#[test]
fn json_has_the_promised_fields() {
    let r = build(&Params::PAPER, 1e-10).expect("report");
    let v = serde_json::to_value(&r).expect("serialisable");
    for motion in ["classical", "uniform"] {
        for side in ["numerical", "closed_form"] {
            for field in ["T", "R", "v_R", "impact_angle_deg", "s"] {
                assert!(
                    v["table"][motion][side][field].is_f64(),
                    "table.{motion}.{side}.{field}"
                );
            }
        }
    }
    assert!(
        (v["table"]["uniform"]["closed_form"]["T"]
            .as_f64()
            .unwrap_or(0.0)
            - 1.085_038_501_948)
            .abs()
            < 1e-11
    );
}
