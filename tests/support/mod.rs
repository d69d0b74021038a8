//! Shared helpers of the verification tests and example programs.

/// The exit status of an example program's run: success, or the error's message on standard error
/// and failure; a reader that stops early (`| head`, a closed pipe) ends the output quietly.
pub fn finish(result: Result<(), Box<dyn std::error::Error>>) -> std::process::ExitCode {
    match result {
        Ok(()) => std::process::ExitCode::SUCCESS,
        Err(e)
            if e.downcast_ref::<std::io::Error>()
                .is_some_and(|e| e.kind() == std::io::ErrorKind::BrokenPipe) =>
        {
            std::process::ExitCode::SUCCESS
        }
        Err(e) => {
            eprintln!("error: {e}");
            std::process::ExitCode::FAILURE
        }
    }
}

/// The verdict line of an example checked against a closed form: `VERIFIED` when the largest
/// scaled deviation `error` is within `100 × tol` (the limit the paper's own check uses), else
/// `NOT VERIFIED`, and then an `Err`, so that the program exits with failure.
pub fn verdict(
    out: &mut impl std::io::Write,
    error: f64,
    tol: f64,
) -> Result<(), Box<dyn std::error::Error>> {
    let limit = 100.0 * tol;
    if error <= limit {
        writeln!(
            out,
            "VERIFIED: largest scaled deviation from the closed form {error:.1e}, within the limit \
             {limit:.0e} (100 × tol)"
        )?;
        Ok(())
    } else {
        writeln!(
            out,
            "NOT VERIFIED: largest scaled deviation from the closed form {error:.1e}, beyond the \
             limit {limit:.0e} (100 × tol)"
        )?;
        Err(format!("the deviation {error:.1e} exceeds the limit {limit:.0e}").into())
    }
}

/// A command-line value that must be a finite positive number (clap's `value_parser`), so that a
/// bad one is refused with clap's message and exit status 2.
pub fn positive(s: &str) -> Result<f64, String> {
    match s.parse::<f64>() {
        Ok(v) if v.is_finite() && v >= f64::MIN_POSITIVE => Ok(v),
        Ok(v) => Err(format!(
            "must be a finite positive number, at least {:e} (the smallest normal one), got {v:e}",
            f64::MIN_POSITIVE
        )),
        Err(e) => Err(e.to_string()),
    }
}

/// A small error for a table: `0` when exact, otherwise two significant digits (`3.6e-16`).
pub fn sci(v: f64) -> String {
    if v == 0.0 {
        "0".into()
    } else {
        format!("{v:.1e}")
    }
}

/// The line an example ends with: the largest constraint residual and energy-balance error of
/// `sol`, then `note` (empty, or what the balance means for the model, in parentheses), its
/// accepted steps and its status.
pub fn run_summary(sol: &chetaev::Solution, note: &str) -> String {
    format!(
        "constraint residual {:.1e}, energy balance {:.1e}{note}, {} steps, status {:?}",
        sol.max_residual().expect("recorded"),
        chetaev_catalogue::max_energy_balance(sol),
        sol.stats.accepted_steps,
        sol.status
    )
}

/// Relative difference `|a − b| / max(|b|, tiny)`.
pub fn rel_err(a: f64, b: f64) -> f64 {
    (a - b).abs() / b.abs().max(f64::MIN_POSITIVE)
}

/// Euclidean norm of a vector given as a slice.
pub fn norm(v: &[f64]) -> f64 {
    v.iter().map(|x| x * x).sum::<f64>().sqrt()
}

/// Euclidean distance `|a − b|` of two vectors of the same length.
pub fn distance(a: &[f64], b: &[f64]) -> f64 {
    assert_eq!(a.len(), b.len(), "vectors of different lengths");
    a.iter()
        .zip(b)
        .map(|(x, y)| (x - y) * (x - y))
        .sum::<f64>()
        .sqrt()
}

/// Observed order of convergence from errors at step sizes `h` and `h/ratio`.
pub fn observed_order(err_coarse: f64, err_fine: f64, ratio: f64) -> f64 {
    (err_coarse / err_fine).ln() / ratio.ln()
}

/// The README's code, compiled and run as a doctest.
#[cfg(doctest)]
#[doc = include_str!("../../README.md")]
pub struct ReadmeDoctests;

// The guides of docs/ are compiled and run as doctests of `chetaev` (its module `guides`).
