//! The SVG pictures, drawn by `chetaev-plot`.

use chetaev::solution::Series;
use chetaev_plot::{Figure, Style};

use super::quantity_values;
use crate::run::Outcome;
use crate::scene::{Picture, Scene};

/// Component `j` of every vector of a series.
fn column(rows: &Series, j: usize) -> Vec<f64> {
    rows.iter()
        .map(|r| r.get(j).copied().unwrap_or(f64::NAN))
        .collect()
}

fn series(t: &[f64], v: &[f64]) -> Vec<(f64, f64)> {
    t.iter().copied().zip(v.iter().copied()).collect()
}

pub(super) fn figure(scene: &Scene, out: &Outcome, which: Picture) -> Figure {
    let c = &scene.coordinates;
    let title = |what: &str| format!("{}: {what}", scene.name);
    let against_t = |fig: Figure, names: Vec<String>, rows: &Series| -> Figure {
        names.iter().enumerate().fold(fig, |f, (j, name)| {
            f.line(name, &series(&out.t, &column(rows, j)))
        })
    };
    let k_names =
        |sym: &str| -> Vec<String> { (1..=scene.k()).map(|a| format!("{sym}_{a}")).collect() };
    match which {
        Picture::Trajectory if scene.n() >= 2 => {
            let pts: Vec<(f64, f64)> = out.q.iter().map(|q| (q[0], q[1])).collect();
            let mut f = Figure::new(&title("trajectory"))
                .x_label(&c[0])
                .y_label(&c[1])
                .equal_aspect()
                .line("", &pts);
            for e in &out.events {
                f = f.line_styled(
                    out.event_name(e.index),
                    &[(e.q[0], e.q[1])],
                    Style {
                        width: 0.0,
                        markers: true,
                        ..Style::default()
                    },
                );
            }
            f
        }
        Picture::Trajectory | Picture::State => against_t(
            Figure::new(&title("coordinates")).x_label("t"),
            c.clone(),
            &out.q,
        ),
        Picture::Velocity => against_t(
            Figure::new(&title("velocities")).x_label("t"),
            c.iter().map(|x| format!("{x}_dot")).collect(),
            &out.qd,
        ),
        Picture::Acceleration => against_t(
            Figure::new(&title("accelerations")).x_label("t"),
            c.iter().map(|x| format!("{x}_ddot")).collect(),
            &out.qdd,
        ),
        Picture::Multipliers => against_t(
            Figure::new(&title("multipliers")).x_label("t").y_label("μ"),
            k_names("μ"),
            &out.mu,
        ),
        Picture::Force => against_t(
            Figure::new(&title("Chetaev force Φ = Jᵀμ")).x_label("t"),
            c.iter().map(|x| format!("Φ_{x}")).collect(),
            &out.phi,
        ),
        Picture::Residual => {
            let mut abs = Series::new(out.residual.width());
            for r in out.residual.iter() {
                abs.push(&r.iter().map(|v| v.abs()).collect::<Vec<f64>>());
            }
            against_t(
                Figure::new(&title("constraint residual"))
                    .x_label("t")
                    .y_label("|f|")
                    .log_y(),
                k_names("|f|"),
                &abs,
            )
        }
        Picture::Energy => {
            let e0 = out.energy.first().copied().unwrap_or(0.0);
            let de: Vec<f64> = out.energy.iter().map(|e| e - e0).collect();
            Figure::new(&title("energy balance"))
                .x_label("t")
                .line_styled(
                    "E − E(t0)",
                    &series(&out.t, &de),
                    Style {
                        width: 4.0,
                        ..Style::default()
                    },
                )
                .line(
                    "W_Φ (work of the Chetaev force)",
                    &series(&out.t, &out.work),
                )
                .line("∫∂L/∂t dt", &series(&out.t, &out.dl_dt_integral))
                .line_styled(
                    "balance E − E(t0) − W_Φ + ∫∂L/∂t dt",
                    &series(&out.t, &out.balance),
                    Style {
                        dashed: true,
                        ..Style::default()
                    },
                )
        }
        Picture::Quantities => {
            let values: Vec<Vec<f64>> = scene
                .output
                .quantities
                .iter()
                .map(|(_, e)| quantity_values(e, out).collect())
                .collect();
            scene.output.quantities.iter().zip(&values).fold(
                Figure::new(&title("quantities")).x_label("t"),
                |f, ((name, _), v)| f.line(name, &series(&out.t, v)),
            )
        }
    }
}
