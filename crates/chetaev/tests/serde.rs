//! A solution written as JSON with the `serde` feature: every series, the events, the statistics
//! and the status, in the numbers recorded.
#![cfg(feature = "serde")]

use chetaev::prelude::*;

struct Uniform;
impl Lagrangian<2> for Uniform {
    fn lagrangian<R: Real>(&self, _t: R, q: &SVector<R, 2>, qd: &SVector<R, 2>) -> R {
        qd.dot(qd) * 0.5 - q[1] * 10.0
    }
}
impl Constraints<2, 1> for Uniform {
    fn constraints<R: Real>(&self, _t: R, _q: &SVector<R, 2>, qd: &SVector<R, 2>) -> SVector<R, 1> {
        SVector::from([qd.dot(qd) - 100.0])
    }
}

#[test]
fn a_solution_serialises_to_json_with_its_events_statistics_and_status() {
    let problem = Problem::new(Uniform, 0.0, [0.0, 5.0].into(), [10.0, 0.0].into()).expect("ok");
    let impact = Event::new("impact", |_t, q: &[f64], _qd: &[f64]| q[1])
        .falling()
        .terminal();
    let o = Options::until(10.0).tolerances(1e-10, 1e-10).event(impact);
    let sol = solve(&problem, Dop853::default(), &o).expect("valid");
    let json: serde_json::Value = serde_json::to_value(&sol).expect("serialisable");
    assert_eq!(json["method"], "Dop853");
    assert_eq!(json["t"].as_array().map(Vec::len), Some(sol.len()));
    assert_eq!(json["q"]["width"], 2);
    assert_eq!(json["q"]["data"][1].as_f64(), Some(sol.q[0][1]));
    assert_eq!(json["mu"]["data"].as_array().map(Vec::len), Some(sol.len()));
    assert_eq!(json["events"][0]["t"].as_f64(), Some(sol.events[0].t));
    assert_eq!(
        json["stats"]["rhs_evaluations"].as_u64(),
        Some(sol.stats.rhs_evaluations as u64)
    );
    assert_eq!(json["status"]["Terminated"]["event"], 0);
}
