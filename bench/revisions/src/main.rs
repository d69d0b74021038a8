//! Times `solve` on the paper's scene (the README's model, to the impact event) with the static
//! path of two revisions of chetaev, in one process, interleaved (A, B, A, B, ...), and prints the
//! median time of each and their ratio, at equal tolerance and at equal error. Usage:
//! `cargo run --release -- [--rounds N] [--event-samples N] [--i-controller] [--route dual] [--reuse]`,
//! or `--build-only` to time building the problem and compiling its equations alone, or
//! `--allocations` to count the heap allocations of one solve of each (exact, not timed).

use std::alloc::{GlobalAlloc, Layout, System};
use std::hint::black_box;
use std::sync::atomic::{AtomicUsize, Ordering};
use std::time::Instant;

/// The system allocator, counting allocations (one relaxed increment each, for both revisions
/// alike) so that `--allocations` can report them.
struct Counting;

static ALLOCATIONS: AtomicUsize = AtomicUsize::new(0);

unsafe impl GlobalAlloc for Counting {
    unsafe fn alloc(&self, layout: Layout) -> *mut u8 {
        ALLOCATIONS.fetch_add(1, Ordering::Relaxed);
        System.alloc(layout)
    }
    unsafe fn alloc_zeroed(&self, layout: Layout) -> *mut u8 {
        ALLOCATIONS.fetch_add(1, Ordering::Relaxed);
        System.alloc_zeroed(layout)
    }
    unsafe fn realloc(&self, ptr: *mut u8, layout: Layout, new_size: usize) -> *mut u8 {
        ALLOCATIONS.fetch_add(1, Ordering::Relaxed);
        System.realloc(ptr, layout, new_size)
    }
    unsafe fn dealloc(&self, ptr: *mut u8, layout: Layout) {
        System.dealloc(ptr, layout)
    }
}

#[global_allocator]
static GLOBAL: Counting = Counting;

/// The allocations (and reallocations) made by `f`.
fn allocations(f: &dyn Fn() -> f64) -> usize {
    let before = ALLOCATIONS.load(Ordering::Relaxed);
    black_box(f());
    ALLOCATIONS.load(Ordering::Relaxed) - before
}

/// The counters of a solve's statistics as text (a macro: the two revisions' `Stats` are two types).
macro_rules! counters {
    ($s:expr) => {{
        let s = &$s;
        format!(
            "rhs {} accepted {} rejected {} events {} output {}",
            s.rhs_evaluations,
            s.accepted_steps,
            s.rejected_steps,
            s.event_evaluations,
            s.output_evaluations
        )
    }};
}

/// The scenes of `--sizes`, written once for both revisions (each module brings its revision's
/// prelude): static chains whose size is a type parameter.
macro_rules! sized_scenes {
    () => {
        /// A planar chain of `N` pendulums (unit lengths and masses) in gravity, the speed of the
        /// first two links held: `W` varies with `q`.
        pub struct Pendulums<const N: usize> {
            c: f64,
        }
        impl<const N: usize> Lagrangian<N> for Pendulums<N> {
            fn lagrangian<R: Real>(&self, _t: R, q: &SVector<R, N>, qd: &SVector<R, N>) -> R {
                let (mut xd, mut yd, mut y, mut l) = (R::zero(), R::zero(), R::zero(), R::zero());
                for i in 0..N {
                    xd += q[i].cos() * qd[i];
                    yd += q[i].sin() * qd[i];
                    y -= q[i].cos();
                    l += (xd * xd + yd * yd) * 0.5 - y * 9.81;
                }
                l
            }
        }
        impl<const N: usize> Constraints<N, 1> for Pendulums<N> {
            fn constraints<R: Real>(
                &self,
                _t: R,
                _q: &SVector<R, N>,
                qd: &SVector<R, N>,
            ) -> SVector<R, 1> {
                SVector::from([qd[0] * qd[0] + qd[1] * qd[1] - self.c])
            }
        }

        /// A chain of `N` unit masses joined by anharmonic springs, the speeds of `K` pairs held
        /// (`W` constant): the catalogue's benchmark chain.
        pub struct Springs<const N: usize, const K: usize> {
            c: [f64; K],
        }
        impl<const N: usize, const K: usize> Lagrangian<N> for Springs<N, K> {
            fn lagrangian<R: Real>(&self, _t: R, q: &SVector<R, N>, qd: &SVector<R, N>) -> R {
                let mut l = qd.dot(qd) * 0.5;
                for i in 0..N - 1 {
                    let s = q[i + 1] - q[i] - 1.0;
                    let s2 = s * s;
                    l -= s2 * 0.5 + s2 * s2 * 0.125;
                }
                l
            }
        }
        impl<const N: usize, const K: usize> Constraints<N, K> for Springs<N, K> {
            fn constraints<R: Real>(
                &self,
                _t: R,
                _q: &SVector<R, N>,
                qd: &SVector<R, N>,
            ) -> SVector<R, K> {
                SVector::from_fn(|a, _| {
                    qd[2 * a] * qd[2 * a] + qd[2 * a + 1] * qd[2 * a + 1] - self.c[a]
                })
            }
        }

        /// One solve of a problem to `t_end` with `method` at `tol`: the final `q` and the
        /// counters.
        fn sized_solve<M: Model>(
            problem: &Problem<M>,
            t_end: f64,
            method: &str,
            tol: f64,
        ) -> (Vec<f64>, String) {
            let o = Options::until(t_end).tolerances(tol, tol).output_final();
            let method = AnyMethod::from_name(method, None).expect("a method with error control");
            let sol = solve(problem, method, &o).expect("solved");
            (
                sol.q.last().expect("recorded").to_vec(),
                counters!(sol.stats),
            )
        }

        fn pendulums<const N: usize>(method: &str, tol: f64) -> (Vec<f64>, String) {
            let q = SVector::<f64, N>::from_fn(|i, _| 0.3 + 0.1 * i as f64);
            let qd = SVector::<f64, N>::from_fn(|i, _| 0.2 * (i as f64).cos());
            let c = qd[0] * qd[0] + qd[1] * qd[1];
            let problem = Problem::new(Pendulums::<N> { c }, 0.0, q, qd).expect("valid");
            sized_solve(&problem, 5.0, method, tol)
        }

        fn springs<const N: usize, const K: usize>(method: &str, tol: f64) -> (Vec<f64>, String) {
            let q = SVector::<f64, N>::from_fn(|i, _| i as f64 + 0.1 * (i as f64).sin());
            let qd = SVector::<f64, N>::from_fn(|i, _| 0.3 + 0.2 * (i as f64).cos());
            let c = std::array::from_fn(|a| qd[2 * a] * qd[2 * a] + qd[2 * a + 1] * qd[2 * a + 1]);
            let problem = Problem::new(Springs::<N, K> { c }, 0.0, q, qd).expect("valid");
            sized_solve(&problem, 10.0, method, tol)
        }

        /// One solve of `scene` (`pendulums` or `springs`) of `n` coordinates: the final `q` and
        /// the counters.
        pub fn sized(scene: &str, n: usize, method: &str, tol: f64) -> (Vec<f64>, String) {
            match (scene, n) {
                ("pendulums", 2) => pendulums::<2>(method, tol),
                ("pendulums", 3) => pendulums::<3>(method, tol),
                ("pendulums", 4) => pendulums::<4>(method, tol),
                ("pendulums", 6) => pendulums::<6>(method, tol),
                ("pendulums", 8) => pendulums::<8>(method, tol),
                ("pendulums", 12) => pendulums::<12>(method, tol),
                ("pendulums", 16) => pendulums::<16>(method, tol),
                ("springs", 4) => springs::<4, 2>(method, tol),
                ("springs", 6) => springs::<6, 3>(method, tol),
                ("springs", 8) => springs::<8, 4>(method, tol),
                ("springs", 10) => springs::<10, 5>(method, tol),
                ("springs", 12) => springs::<12, 6>(method, tol),
                ("springs", 16) => springs::<16, 8>(method, tol),
                ("springs", 24) => springs::<24, 12>(method, tol),
                _ => panic!("no {scene} of {n} coordinates"),
            }
        }
    };
}

mod base {
    use chetaev_base::prelude::*;

    sized_scenes!();

    pub struct Uniform {
        pub m: f64,
        pub g: f64,
        pub v0: f64,
    }
    impl Lagrangian<2> for Uniform {
        fn lagrangian<R: Real>(&self, _t: R, q: &SVector<R, 2>, qd: &SVector<R, 2>) -> R {
            qd.dot(qd) * (0.5 * self.m) - q[1] * (self.m * self.g)
        }
    }
    impl Constraints<2, 1> for Uniform {
        fn constraints<R: Real>(
            &self,
            _t: R,
            _q: &SVector<R, 2>,
            qd: &SVector<R, 2>,
        ) -> SVector<R, 1> {
            SVector::from([qd.dot(qd) - self.v0 * self.v0])
        }
    }

    fn problem() -> Problem<chetaev_base::model::Fixed<Uniform, 2, 1>> {
        let model = Uniform {
            m: 1.0,
            g: 10.0,
            v0: 10.0,
        };
        Problem::new(
            model,
            0.0,
            SVector::from([0.0, 5.0]),
            SVector::from([10.0, 0.0]),
        )
        .expect("valid")
    }

    /// Builds the problem and compiles its equations (what the first solve does before it
    /// steps); returns the initial time, to be kept.
    pub fn build() -> f64 {
        let problem = problem();
        std::hint::black_box(problem.compiled());
        problem.t0()
    }

    /// One solve to the impact, read by `read` (inlined, so that [`run`] is what it was before
    /// [`stats`] existed).
    #[inline(always)]
    fn solved<T>(method: &str, tol: f64, read: impl FnOnce(&Solution) -> T) -> T {
        let problem = problem();
        let impact = Event::new("impact", |_t, q, _qd| q[1]).falling().terminal();
        let o = Options::until(10.0).tolerances(tol, tol).event(impact);
        let o = if crate::every_step() {
            o
        } else {
            o.output_final()
        };
        let sol = match method {
            "dop853" => solve(&problem, Dop853::default(), &o),
            "rodas4" => solve(&problem, Rodas4, &o),
            "rodas5p" => solve(&problem, Rodas5P, &o),
            _ => solve(&problem, Dopri5::default(), &o),
        }
        .expect("solved");
        read(&sol)
    }

    /// One solve to the impact; returns the impact time.
    pub fn run(method: &str, tol: f64) -> f64 {
        solved(method, tol, |sol| sol.events[0].t)
    }

    /// The counters of one solve to the impact, as text.
    pub fn stats(method: &str, tol: f64) -> String {
        solved(method, tol, |sol| counters!(sol.stats))
    }
}

mod head {
    use chetaev::prelude::*;

    sized_scenes!();

    pub struct Uniform {
        pub m: f64,
        pub g: f64,
        pub v0: f64,
    }
    impl Lagrangian<2> for Uniform {
        fn lagrangian<R: Real>(&self, _t: R, q: &SVector<R, 2>, qd: &SVector<R, 2>) -> R {
            qd.dot(qd) * (0.5 * self.m) - q[1] * (self.m * self.g)
        }
    }
    impl Constraints<2, 1> for Uniform {
        fn constraints<R: Real>(
            &self,
            _t: R,
            _q: &SVector<R, 2>,
            qd: &SVector<R, 2>,
        ) -> SVector<R, 1> {
            SVector::from([qd.dot(qd) - self.v0 * self.v0])
        }
    }

    fn problem() -> Problem<chetaev::model::Fixed<Uniform, 2, 1>> {
        let model = Uniform {
            m: 1.0,
            g: 10.0,
            v0: 10.0,
        };
        let problem = Problem::new(
            model,
            0.0,
            SVector::from([0.0, 5.0]),
            SVector::from([10.0, 0.0]),
        )
        .expect("valid");
        if crate::dual_route() {
            problem.with_route(Route::Dual)
        } else {
            problem
        }
    }

    /// [`super::base::build`] of this revision.
    pub fn build() -> f64 {
        let problem = problem();
        std::hint::black_box(problem.compiled());
        problem.t0()
    }

    /// One solve to the impact, read by `read` (inlined, so that [`run`] is what it was before
    /// [`stats`] existed). The problem (with its compiled equations) is built in every run, or
    /// once with `--reuse`.
    #[inline(always)]
    fn solved<T>(method: &str, tol: f64, read: impl FnOnce(&Solution) -> T) -> T {
        static REUSED: std::sync::OnceLock<Problem<chetaev::model::Fixed<Uniform, 2, 1>>> =
            std::sync::OnceLock::new();
        let fresh;
        let problem = if crate::reuse() {
            REUSED.get_or_init(problem)
        } else {
            fresh = problem();
            &fresh
        };
        let impact = Event::new("impact", |_t, q, _qd| q[1]).falling().terminal();
        let o = Options::until(10.0).tolerances(tol, tol).event(impact);
        let o = if crate::every_step() {
            o
        } else {
            o.output_final()
        };
        let (samples, i_controller) = crate::settings();
        let o = o.event_samples(samples);
        let o = if i_controller {
            o.controller(Controller::i(0.2, 10.0))
        } else {
            o
        };
        let sol = match method {
            "dop853" => solve(problem, Dop853::default(), &o),
            "rodas4" => solve(problem, Rodas4, &o),
            "rodas5p" => solve(problem, Rodas5P, &o),
            _ => solve(problem, Dopri5::default(), &o),
        }
        .expect("solved");
        read(&sol)
    }

    /// One solve to the impact; returns the impact time.
    pub fn run(method: &str, tol: f64) -> f64 {
        solved(method, tol, |sol| sol.events[0].t)
    }

    /// The counters of one solve to the impact, as text.
    pub fn stats(method: &str, tol: f64) -> String {
        solved(method, tol, |sol| counters!(sol.stats))
    }
}

/// `--route dual`: the head evaluates by dual numbers (no compiled equations).
fn dual_route() -> bool {
    flag("dual")
}

/// `--every-step`: both revisions record at every step, everything (the library's default output)
/// instead of at the end only.
fn every_step() -> bool {
    flag("--every-step")
}

/// `--reuse`: the head builds its problem once (the compiled equations made once) instead of in
/// every run.
fn reuse() -> bool {
    flag("--reuse")
}

/// Whether the command line has `word`, read once: reading it allocates, and the head asks in
/// every run, which the base does not.
fn flag(word: &str) -> bool {
    static ARGS: std::sync::OnceLock<Vec<String>> = std::sync::OnceLock::new();
    ARGS.get_or_init(|| std::env::args().collect())
        .iter()
        .any(|a| a == word)
}

/// Settings of the head's runs: `--event-samples N` (default 4, the library's default) and
/// `--i-controller` (the classical controller for every method, as the base had).
fn settings() -> (usize, bool) {
    static SETTINGS: std::sync::OnceLock<(usize, bool)> = std::sync::OnceLock::new();
    *SETTINGS.get_or_init(parse_settings)
}

/// Reads the settings of [`settings`] from the command line (once).
fn parse_settings() -> (usize, bool) {
    let args: Vec<String> = std::env::args().collect();
    let samples = args
        .iter()
        .position(|a| a == "--event-samples")
        .and_then(|i| args.get(i + 1))
        .and_then(|s| s.parse().ok())
        .unwrap_or(4);
    (samples, args.iter().any(|a| a == "--i-controller"))
}

fn median(v: &mut [f64]) -> f64 {
    v.sort_by(f64::total_cmp);
    v[v.len() / 2]
}

/// Seconds per call of `f`, over a batch of `n` calls.
fn time(n: usize, f: &dyn Fn() -> f64) -> f64 {
    let t0 = Instant::now();
    for _ in 0..n {
        black_box(f());
    }
    t0.elapsed().as_secs_f64() / n as f64
}

/// `log t` at `log e` on the polyline through `(log e_i, log t_i)` (sorted by error), or `None`
/// outside its range: a ratio at equal error is read only where both curves were measured.
fn time_at_error(points: &[(f64, f64)], e: f64) -> Option<f64> {
    let mut p: Vec<(f64, f64)> = points.iter().map(|&(e, t)| (e.ln(), t.ln())).collect();
    p.sort_by(|a, b| a.0.total_cmp(&b.0));
    let x = e.ln();
    p.windows(2).find_map(|w| {
        let ((x0, y0), (x1, y1)) = (w[0], w[1]);
        (x >= x0 && x <= x1 && x1 > x0).then(|| (y0 + (y1 - y0) * (x - x0) / (x1 - x0)).exp())
    })
}

/// `--sizes`: the chains of `sized_scenes!` at several sizes, one tolerance, interleaved; the
/// counters of both revisions and how far their final `q` differ, so that the ratio compares the
/// same steps.
fn sizes(rounds: usize, methods: &[String]) {
    let tol = 1e-8;
    println!(
        "static chains to their end time at tol = {tol:.0e}, median of {rounds} interleaved rounds"
    );
    println!(
        "{:10} {:>3} {:8} {:>12} {:>12} {:>9} {:>10} {:>8}",
        "scene", "n", "method", "base [µs]", "head [µs]", "head/base", "|Δq|max", "same work"
    );
    let cases = [
        ("pendulums", [2, 3, 4, 6, 8, 12, 16].as_slice()),
        ("springs", [4, 6, 8, 10, 12, 16, 24].as_slice()),
    ];
    // `--scene NAME`: that scene alone.
    let args: Vec<String> = std::env::args().collect();
    let only = args
        .iter()
        .position(|a| a == "--scene")
        .and_then(|i| args.get(i + 1));
    for (scene, ns) in cases {
        if only.is_some_and(|o| o != scene) {
            continue;
        }
        for &n in ns {
            for method in methods.iter().map(String::as_str) {
                let (qa, ca) = base::sized(scene, n, method, tol);
                let (qb, cb) = head::sized(scene, n, method, tol);
                let dq = qa
                    .iter()
                    .zip(&qb)
                    .map(|(a, b)| (a - b).abs())
                    .fold(0.0, f64::max);
                let single = time(3, &|| head::sized(scene, n, method, tol).0[0]);
                let reps = ((2e-2 / single) as usize).max(1);
                let (mut a, mut b) = (Vec::new(), Vec::new());
                for _ in 0..rounds {
                    a.push(time(reps, &|| base::sized(scene, n, method, tol).0[0]));
                    b.push(time(reps, &|| head::sized(scene, n, method, tol).0[0]));
                }
                let (a, b) = (median(&mut a), median(&mut b));
                println!(
                    "{scene:10} {n:>3} {method:8} {:>12.1} {:>12.1} {:>9.3} {dq:>10.1e} {:>8}",
                    a * 1e6,
                    b * 1e6,
                    b / a,
                    if ca == cb { "yes" } else { "no" }
                );
                if ca != cb {
                    println!("  base: {ca}\n  head: {cb}");
                }
            }
        }
    }
}

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let rounds: usize = args
        .iter()
        .position(|a| a == "--rounds")
        .and_then(|i| args.get(i + 1))
        .and_then(|s| s.parse().ok())
        .unwrap_or(21);
    if args.iter().any(|a| a == "--build-only") {
        // Building the problem and compiling its equations alone, without a solve.
        let n = ((2e-3 / time(20, &head::build)) as usize).max(5);
        let (mut a, mut b) = (Vec::new(), Vec::new());
        for _ in 0..rounds {
            a.push(time(n, &base::build));
            b.push(time(n, &head::build));
        }
        let (a, b) = (median(&mut a), median(&mut b));
        println!(
            "building the paper's problem and compiling its equations, median of {rounds} \
             interleaved rounds: base {:.2} µs, head {:.2} µs, head/base {:.3}",
            a * 1e6,
            b * 1e6,
            b / a
        );
        return;
    }
    // `--methods a,b`: which of dopri5, dop853, rodas4, rodas5p (default dopri5,dop853).
    let methods: Vec<String> = args
        .iter()
        .position(|a| a == "--methods")
        .and_then(|i| args.get(i + 1))
        .map_or_else(|| "dopri5,dop853".to_string(), Clone::clone)
        .split(',')
        .map(str::to_string)
        .collect();
    if args.iter().any(|a| a == "--sizes") {
        sizes(rounds, &methods);
        return;
    }
    if args.iter().any(|a| a == "--allocations") {
        println!(
            "heap allocations of one run (problem built, its equations compiled, solved): base, head"
        );
        // Once each first, so that what is made once per process (the head reads its settings
        // from the command line at its first run) is not counted.
        black_box((base::run("dopri5", 1e-6), head::run("dopri5", 1e-6)));
        println!(
            "build only: {}, {}",
            allocations(&base::build),
            allocations(&head::build)
        );
        for method in methods.iter().map(String::as_str) {
            for e in [6, 9, 13] {
                let tol = 10f64.powi(-e);
                println!(
                    "{method} {tol:.0e}: {}, {}",
                    allocations(&|| base::run(method, tol)),
                    allocations(&|| head::run(method, tol))
                );
                println!("  base: {}", base::stats(method, tol));
                println!("  head: {}", head::stats(method, tol));
            }
        }
        return;
    }
    let (samples, i_controller) = settings();
    println!(
        "head: event_samples = {samples}, controller = {}",
        if i_controller {
            "I (0.2, 10) for every method"
        } else {
            "each method's own"
        }
    );
    println!(
        "head: route = {}, problem {}",
        if dual_route() {
            "dual"
        } else {
            "graph (compiled equations)"
        },
        if reuse() {
            "built once and reused"
        } else {
            "built in every run (its compilation included)"
        }
    );
    let exact = 0.5f64.exp().acosh();
    let output = if every_step() {
        "output at every step, everything recorded"
    } else {
        "output final"
    };
    println!("paper scene (README model) to the impact event, {output}; median of {rounds} interleaved rounds");
    println!(
        "{:8} {:>6} {:>10} {:>10} {:>9} {:>9} {:>8} {:>12}",
        "method", "tol", "base [µs]", "head [µs]", "err base", "err head", "at tol", "at equal err"
    );
    for method in methods.iter().map(String::as_str) {
        let mut rows = Vec::new();
        for e in 6..=13 {
            let tol = 10f64.powi(-e);
            let (eb, eh) = (
                (base::run(method, tol) - exact).abs(),
                (head::run(method, tol) - exact).abs(),
            );
            let single = time(20, &|| head::run(method, tol));
            let n = ((2e-3 / single) as usize).max(5);
            let (mut a, mut b) = (Vec::new(), Vec::new());
            for _ in 0..rounds {
                a.push(time(n, &|| base::run(method, tol)));
                b.push(time(n, &|| head::run(method, tol)));
            }
            rows.push((
                tol,
                median(&mut a),
                median(&mut b),
                eb.max(1e-16),
                eh.max(1e-16),
            ));
        }
        let base_curve: Vec<(f64, f64)> = rows.iter().map(|r| (r.3, r.1)).collect();
        let mut ratios = Vec::new();
        for &(tol, ta, tb, eb, eh) in &rows {
            let at_err = time_at_error(&base_curve, eh).map(|t| tb / t);
            if let Some(r) = at_err {
                ratios.push(r);
            }
            println!(
                "{method:8} {tol:>6.0e} {:>10.2} {:>10.2} {eb:>9.1e} {eh:>9.1e} {:>8.3} {:>12}",
                ta * 1e6,
                tb * 1e6,
                tb / ta,
                at_err.map_or("-".to_string(), |r| format!("{r:.3}"))
            );
        }
        let geo = (ratios.iter().map(|r| r.ln()).sum::<f64>() / ratios.len().max(1) as f64).exp();
        println!(
            "{method:8} head/base at equal error: geometric mean {geo:.3} over {} tolerances",
            ratios.len()
        );
    }
}
