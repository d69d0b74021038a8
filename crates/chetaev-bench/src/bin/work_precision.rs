//! `work-precision`: error against run time for every scene and method, the limit set by the
//! paper's model written out by hand, and the cost of constraints and diagnostics that a problem
//! does not use. Writes CSV, Markdown and SVG into `--out` (default
//! `./chetaev-bench-out/work-precision`; the committed report is regenerated with
//! `--out docs/performance`), with `work-precision.json`, every measured point, from which
//! `merge` writes the rest again. Prints a summary.
//!
//! The study is a list of items: for each scene, all methods at one tolerance, or `Rk4` at one
//! step count; the same for the limit; then each comparison of the overheads. With
//! `--shard k/n` only the items `i` with `i mod n = k − 1` are run and written to
//! `work-precision.part-k-of-n.json`; `work-precision merge` joins the `n` parts into the files of
//! the whole run (see `docs/sweeps.md`).
//!
//! ```sh
//! cargo run --release -p chetaev-bench --bin work-precision -- --out docs/performance
//! cargo run --release -p chetaev-bench --bin work-precision -- --quick --out /tmp/wp
//! cargo run --release -p chetaev-bench --bin work-precision -- --shard 3/8 --out parts
//! cargo run --release -p chetaev-bench --bin work-precision -- merge --out wp parts/work-precision.part-*-of-8.json
//! ```

use std::error::Error;
use std::fmt::Write as _;
use std::io::Write as _;
use std::path::{Path, PathBuf};
use std::process::ExitCode;
use std::time::Instant;

use chetaev::prelude::*;
use chetaev_bench::cli::{exit, output_dir, print_summary, refuse_argument};
use chetaev_bench::measure::{ratio_at_error, Budget};
use chetaev_bench::overhead::{constraint_overhead, diagnostics_overhead, Comparison};
use chetaev_bench::parts::{
    comparison_from_json, comparison_to_json, number, point_from_json, point_to_json, read_number,
    Fields, Part, Shard,
};
use chetaev_bench::report::{
    format_ratio, format_seconds, points_csv, points_markdown, ratio_at_tolerance_markdown,
    ratio_markdown,
};
use chetaev_bench::scenes;
use chetaev_bench::study::{
    curve, run_limit, run_scene, study_methods, Point, PointOutcome, StudyConfig, StudyScene,
};
use chetaev_plot::{Figure, Style};
use clap::{Args, Parser, Subcommand};
use serde_json::{json, Value};

/// Error against run time for chetaev's methods, ode_solvers and hand-written right-hand sides.
#[derive(Parser, Debug)]
#[command(
    name = "work-precision",
    version,
    args_conflicts_with_subcommands = true
)]
struct Cli {
    #[command(subcommand)]
    command: Option<Command>,
    #[command(flatten)]
    run: RunArgs,
}

#[derive(Subcommand, Debug)]
enum Command {
    /// Join the part files of `--shard k/n` runs into the output of the whole study.
    Merge(MergeArgs),
}

#[derive(Args, Debug)]
struct RunArgs {
    /// Output directory for CSV, Markdown, SVG and JSON
    /// [default: ./chetaev-bench-out/work-precision].
    #[arg(long)]
    out: Option<PathBuf>,
    /// A smoke run: four tolerances, four Rk4 step counts, one timed run each (seconds, not
    /// minutes; the numbers are not for publishing).
    #[arg(long)]
    quick: bool,
    /// Run only shard K of N (K from 1 to N): the items i, counted from 0, with i mod N = K − 1;
    /// writes work-precision.part-K-of-N.json for `merge`.
    #[arg(long, value_name = "K/N")]
    shard: Option<Shard>,
    /// Tolerances of the adaptive methods, comma-separated (replacing 1e-3 … 1e-14, or the four
    /// of --quick).
    #[arg(
        long,
        value_delimiter = ',',
        value_name = "TOL,...",
        allow_hyphen_values = true
    )]
    tolerances: Option<Vec<f64>>,
    /// Step counts of Rk4, comma-separated (replacing 8, 16, …, 32768, or the four of --quick).
    #[arg(long, value_delimiter = ',', value_name = "N,...")]
    rk4_steps: Option<Vec<usize>>,
    /// Step limit of every adaptive run of the scenes, accepted plus rejected [default: 200000];
    /// Rk4 takes the step counts of --rk4-steps, the ode_solvers runs never more than that
    /// crate's own limit, 100000, and the overhead comparisons, of fixed short solves, their own.
    #[arg(long)]
    max_steps: Option<usize>,
}

#[derive(Args, Debug)]
struct MergeArgs {
    /// Output directory [default: ./chetaev-bench-out/work-precision].
    #[arg(long)]
    out: Option<PathBuf>,
    /// The part files of all N shards (work-precision.part-K-of-N.json); a merged
    /// work-precision.json also counts as all of its shards.
    #[arg(required = true)]
    parts: Vec<PathBuf>,
}

/// The error levels at which curves are compared.
const COMPARE_AT: [f64; 6] = [1e-6, 1e-8, 1e-10, 1e-11, 1e-12, 1e-13];

/// The colours of the methods' lines (Okabe and Ito's palette, for colour-blind readers), by
/// name; a method without one here takes the next of [`SPARE_COLOURS`].
/// The same method has the same colour in every diagram; ode_solvers' Dopri5 and Dop853 take the
/// colour of the method they implement, dashed.
const COLOURS: [(&str, &str); 6] = [
    ("Dopri5", "#0072B2"),
    ("Dop853", "#D55E00"),
    ("Tsit5", "#000000"),
    ("Rodas4", "#009E73"),
    ("Rodas5P", "#E69F00"),
    ("Rk4", "#CC79A7"),
];

/// The colours left for methods not in [`COLOURS`], in turn (Okabe and Ito's sky blue, then
/// brown and grey; no yellow, which is too light on white).
const SPARE_COLOURS: [&str; 3] = ["#56B4E9", "#8C564B", "#808080"];

/// chetaev's methods in the order of the tables ([`study_methods`]), with the colour of their
/// lines.
fn methods() -> Vec<(&'static str, &'static str)> {
    let mut spare = SPARE_COLOURS.iter().cycle();
    study_methods()
        .into_iter()
        .map(|name| {
            let colour = COLOURS.iter().find(|(m, _)| *m == name).map(|(_, c)| *c);
            (
                name,
                colour
                    .or_else(|| spare.next().copied())
                    .unwrap_or("#000000"),
            )
        })
        .collect()
}

/// The methods of a scene in the order of its tables and CSV: chetaev's, then ode_solvers'.
fn scene_order() -> Vec<&'static str> {
    let mut order: Vec<&'static str> = methods().into_iter().map(|(m, _)| m).collect();
    order.extend(["Dopri5 (ode_solvers)", "Dop853 (ode_solvers)"]);
    order
}

/// The number of comparisons in the overheads.
const OVERHEADS: usize = 6;

fn main() -> ExitCode {
    exit("work-precision", run())
}

/// Progress on stderr; a closed stderr only silences it.
fn note(message: std::fmt::Arguments<'_>) {
    let _ = writeln!(std::io::stderr(), "{message}");
}

fn run() -> Result<(), Box<dyn Error>> {
    let cli = Cli::parse();
    let (out, summary) = match cli.command {
        Some(Command::Merge(m)) => {
            let out = output_dir(m.out, "work-precision")?;
            let summary = merge_parts(&m.parts, &out)?;
            (out, summary)
        }
        None => {
            let settings =
                Settings::from_args(&cli.run).unwrap_or_else(|m| refuse_argument::<Cli>(m));
            let out = output_dir(cli.run.out.clone(), "work-precision")?;
            let summary = run_study(&cli.run, &settings, &out)?;
            (out, summary)
        }
    };
    print_summary(&summary, &out)
}

/// The most steps of one Rk4 run: 10⁷ steps of the largest scene take minutes.
const MAX_RK4_STEPS: usize = 10_000_000;

/// What defines the study's items, equal in all parts of one run.
#[derive(Clone, Debug, PartialEq)]
struct Settings {
    /// Tolerances, loosest first.
    tolerances: Vec<f64>,
    /// Step counts of `Rk4` for every scene that runs it and for the limit; `None` keeps each
    /// scene's own.
    rk4_steps: Option<Vec<usize>>,
    budget: Budget,
    max_steps: usize,
}

impl Settings {
    /// The settings of `args`, or what is wrong with them.
    fn from_args(args: &RunArgs) -> Result<Self, String> {
        let config = StudyConfig::default();
        let mut s = Self {
            tolerances: config.tolerances,
            rk4_steps: None,
            budget: config.budget,
            max_steps: config.max_steps,
        };
        if args.quick {
            // Within the library's floor, rtol ≥ 100 ulps ≈ 2.2e-14 (Options::validate): a smoke
            // run measures every tolerance it lists. (The full list goes to 1e-14 on purpose, to
            // record the refusal in the published tables; docs/performance.md says so.)
            s.tolerances = vec![1e-4, 1e-8, 1e-12, 1e-13];
            s.budget = Budget {
                min_repeats: 1,
                max_repeats: 1,
                min_seconds: 0.0,
            };
            s.rk4_steps = Some(vec![16, 256, 4096, 16384]);
        }
        if let Some(t) = &args.tolerances {
            if t.is_empty() || t.iter().any(|&t| !(t > 0.0 && t < 1.0)) {
                return Err(
                    "--tolerances needs relative tolerances between 0 and 1, e.g. --tolerances \
                     1e-4,1e-8"
                        .into(),
                );
            }
            let mut t = t.clone();
            t.sort_by(|a, b| b.total_cmp(a));
            t.dedup();
            s.tolerances = t;
        }
        if let Some(r) = &args.rk4_steps {
            if r.iter().any(|&n| !(1..=MAX_RK4_STEPS).contains(&n)) {
                return Err(format!(
                    "--rk4-steps needs step counts from 1 to {MAX_RK4_STEPS}, e.g. --rk4-steps \
                     16,256"
                ));
            }
            let mut r = r.clone();
            r.sort_unstable();
            r.dedup();
            s.rk4_steps = Some(r);
        }
        if let Some(m) = args.max_steps {
            if m == 0 {
                return Err("--max-steps needs at least 1".into());
            }
            s.max_steps = m;
        }
        Ok(s)
    }

    fn config(&self) -> StudyConfig {
        StudyConfig {
            tolerances: self.tolerances.clone(),
            budget: self.budget,
            max_steps: self.max_steps,
        }
    }

    fn to_json(&self) -> Value {
        json!({
            "tolerances": self.tolerances.iter().map(|&t| number(t)).collect::<Vec<_>>(),
            "rk4_steps": self.rk4_steps,
            "budget": {
                "min_repeats": self.budget.min_repeats,
                "max_repeats": self.budget.max_repeats,
                "min_seconds": number(self.budget.min_seconds),
            },
            "max_steps": self.max_steps,
        })
    }

    fn from_json(v: &Value) -> Result<Self, Box<dyn Error>> {
        let f = Fields::of(v, "settings")?;
        let tolerances = f
            .array("tolerances")?
            .iter()
            .map(read_number)
            .collect::<Option<Vec<_>>>()
            .ok_or("`tolerances` of the settings are not numbers")?;
        let rk4_steps = match f.get("rk4_steps")? {
            Value::Null => None,
            Value::Array(a) => Some(
                a.iter()
                    .map(|n| n.as_u64().and_then(|n| usize::try_from(n).ok()))
                    .collect::<Option<Vec<usize>>>()
                    .ok_or("`rk4_steps` of the settings are not counts")?,
            ),
            _ => return Err("`rk4_steps` of the settings is not a list".into()),
        };
        let b = Fields::of(f.get("budget")?, "budget")?;
        Ok(Self {
            tolerances,
            rk4_steps,
            budget: Budget {
                min_repeats: b.usize("min_repeats")?,
                max_repeats: b.usize("max_repeats")?,
                min_seconds: b.f64("min_seconds")?,
            },
            max_steps: f.usize("max_steps")?,
        })
    }
}

/// One setting of a method: a tolerance, a step count of the methods without error control
/// (`Rk4`), or those refused by the scene.
#[derive(Clone, Copy, Debug, PartialEq)]
enum Setting {
    Tolerance(f64),
    Steps(usize),
    StepsRefused,
}

impl std::fmt::Display for Setting {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            Self::Tolerance(t) => write!(f, "tolerance {t:e}"),
            Self::Steps(n) => write!(f, "{n} fixed steps"),
            Self::StepsRefused => f.write_str("fixed steps (refused)"),
        }
    }
}

/// One item of the study: every method of a scene at one setting, chetaev and the hand-written
/// systems at one setting, or one comparison of the overheads.
#[derive(Clone, Copy, Debug, PartialEq)]
enum Item {
    Scene(usize, Setting),
    Limit(Setting),
    Overhead(usize),
}

/// A scene of the study, whatever its model and sizes.
trait AnyScene {
    fn key(&self) -> &'static str;
    fn title(&self) -> &str;
    fn reference(&self) -> &str;
    /// The settings of the scene's items: the tolerances, then the step counts of `Rk4`.
    fn settings(&self, tolerances: &[f64]) -> Vec<Setting>;
    /// Every method of the scene at `setting`, in the order of [`run_scene`].
    fn run(&mut self, config: &StudyConfig, setting: Setting) -> Vec<Point>;
}

impl<M: Model> AnyScene for StudyScene<M> {
    fn key(&self) -> &'static str {
        self.key
    }

    fn title(&self) -> &str {
        &self.title
    }

    fn reference(&self) -> &str {
        &self.reference
    }

    fn settings(&self, tolerances: &[f64]) -> Vec<Setting> {
        let mut s: Vec<Setting> = tolerances.iter().map(|&t| Setting::Tolerance(t)).collect();
        match &self.fixed_steps {
            Ok(steps) => s.extend(steps.iter().map(|&n| Setting::Steps(n))),
            Err(_) => s.push(Setting::StepsRefused),
        }
        s
    }

    fn run(&mut self, config: &StudyConfig, setting: Setting) -> Vec<Point> {
        let mut config = config.clone();
        let rk4 = match setting {
            Setting::Tolerance(t) => {
                config.tolerances = vec![t];
                Ok(Vec::new())
            }
            Setting::Steps(n) => {
                config.tolerances = Vec::new();
                Ok(vec![n])
            }
            Setting::StepsRefused => {
                config.tolerances = Vec::new();
                self.fixed_steps.clone()
            }
        };
        let own = std::mem::replace(&mut self.fixed_steps, rk4);
        let points = run_scene(self, &config, &mut |_| {});
        self.fixed_steps = own;
        points
    }
}

/// The paper's scene, run against the hand-written systems.
trait LimitScene {
    /// chetaev and the two hand-written systems at `setting`, in the order of [`run_limit`].
    fn run(&self, config: &StudyConfig, setting: Setting) -> Vec<Point>;
}

impl<M: Model> LimitScene for StudyScene<M> {
    fn run(&self, config: &StudyConfig, setting: Setting) -> Vec<Point> {
        let (reduced, full) = (scenes::reduced_handwritten(), scenes::full_handwritten());
        let mut config = config.clone();
        config.tolerances = Vec::new();
        let steps = match setting {
            Setting::Tolerance(t) => {
                config.tolerances = vec![t];
                Vec::new()
            }
            Setting::Steps(n) => vec![n],
            Setting::StepsRefused => Vec::new(),
        };
        run_limit(self, &reduced, &full, &config, &steps)
    }
}

/// Boxes a scene, with the step counts of `Rk4` replaced where it runs `Rk4` and `rk4` says so.
fn boxed<M>(mut scene: StudyScene<M>, rk4: Option<&Vec<usize>>) -> Box<dyn AnyScene>
where
    M: Model + 'static,
{
    if let (Some(steps), Ok(_)) = (rk4, &scene.fixed_steps) {
        scene.fixed_steps = Ok(steps.clone());
    }
    Box::new(scene)
}

/// The scenes and settings of a study, and its items.
struct Study {
    config: StudyConfig,
    scenes: Vec<Box<dyn AnyScene>>,
    limit: Box<dyn LimitScene>,
    limit_rk4_steps: Vec<usize>,
}

impl Study {
    fn new(settings: &Settings) -> Result<Self, Box<dyn Error>> {
        let config = settings.config();
        let rk4 = settings.rk4_steps.as_ref();
        let scenes = vec![
            boxed(scenes::uniform_scene()?, rk4),
            boxed(scenes::classical_scene()?, rk4),
            boxed(scenes::stiff_scene(config.max_steps)?, rk4),
            boxed(scenes::particle3d_scene()?, rk4),
            boxed(scenes::two_runners_scene()?, rk4),
        ];
        Ok(Self {
            scenes,
            limit: Box::new(scenes::uniform_scene()?),
            limit_rk4_steps: settings
                .rk4_steps
                .clone()
                .unwrap_or_else(scenes::fixed_steps),
            config,
        })
    }

    /// The items in the order of their indices: the scenes' (tolerances, then `Rk4`), the
    /// limit's, the overheads.
    fn plan(&self) -> Vec<Item> {
        let mut items = Vec::new();
        for (s, scene) in self.scenes.iter().enumerate() {
            items.extend(
                scene
                    .settings(&self.config.tolerances)
                    .into_iter()
                    .map(|setting| Item::Scene(s, setting)),
            );
        }
        items.extend(
            self.config
                .tolerances
                .iter()
                .map(|&t| Item::Limit(Setting::Tolerance(t))),
        );
        items.extend(
            self.limit_rk4_steps
                .iter()
                .map(|&n| Item::Limit(Setting::Steps(n))),
        );
        items.extend((0..OVERHEADS).map(Item::Overhead));
        items
    }

    fn describe(&self, item: Item) -> String {
        match item {
            Item::Scene(s, setting) => format!("{}, {setting}", self.scenes[s].key()),
            Item::Limit(setting) => format!("limit, {setting}"),
            Item::Overhead(i) => format!("overhead {}", i + 1),
        }
    }

    /// Runs one item; its result as JSON.
    fn run(&mut self, item: Item) -> Result<Value, Box<dyn Error>> {
        let points = match item {
            Item::Scene(s, setting) => self.scenes[s].run(&self.config, setting),
            Item::Limit(setting) => self.limit.run(&self.config, setting),
            Item::Overhead(i) => {
                let c = overhead(i, &self.config.budget)?;
                return Ok(json!({ "comparison": comparison_to_json(&c) }));
            }
        };
        let points: Vec<Value> = points.iter().map(point_to_json).collect();
        Ok(json!({ "points": points }))
    }
}

/// Comparison `i` of the overheads: an unused constraint, then diagnostics, each with `Dopri5`,
/// `Dop853` and `Rodas4`.
fn overhead(i: usize, b: &Budget) -> Result<Comparison, chetaev_catalogue::Error> {
    let p = scenes::PAPER;
    match i {
        0 => constraint_overhead(&p, Dopri5::default(), 1e-8, b),
        1 => constraint_overhead(&p, Dop853::default(), 1e-12, b),
        2 => constraint_overhead(&p, Rodas4, 1e-10, b),
        3 => diagnostics_overhead(&p, Dopri5::default(), 1e-8, b),
        4 => diagnostics_overhead(&p, Dop853::default(), 1e-12, b),
        _ => diagnostics_overhead(&p, Rodas4, 1e-10, b),
    }
}

/// Runs the study, or one shard of it; writes the part file, and for the whole study the report.
/// Returns the summary for stdout.
fn run_study(args: &RunArgs, settings: &Settings, out: &Path) -> Result<String, Box<dyn Error>> {
    let mut study = Study::new(settings)?;
    let plan = study.plan();
    let shard = args.shard.unwrap_or(Shard::WHOLE);
    let mine: Vec<usize> = shard.items(plan.len()).collect();
    let started = Instant::now();
    let mut items = Vec::with_capacity(mine.len());
    for (done, &i) in mine.iter().enumerate() {
        let start = Instant::now();
        items.push((i, study.run(plan[i])?));
        note(format_args!(
            "[{}/{}] {}: {:.1} s",
            done + 1,
            mine.len(),
            study.describe(plan[i]),
            start.elapsed().as_secs_f64()
        ));
    }
    let elapsed = started.elapsed().as_secs_f64();
    let part = Part::new(
        "work-precision",
        settings.to_json(),
        plan.len(),
        shard,
        json!({ "machine": machine(), "seconds": number(elapsed) }),
        items,
    );
    part.write_into(out)?;
    if shard == Shard::WHOLE {
        return report(&study, &part, out);
    }
    Ok(format!(
        "shard {shard}: {} of {} items in {elapsed:.0} s, in {}\n",
        mine.len(),
        plan.len(),
        part.file_name()
    ))
}

/// Joins the parts and writes the report of the whole study.
fn merge_parts(files: &[PathBuf], out: &Path) -> Result<String, Box<dyn Error>> {
    let whole = Part::read_merged(files, "work-precision")?;
    let study = Study::new(&Settings::from_json(&whole.settings)?)?;
    whole.write_into(out)?;
    report(&study, &whole, out)
}

/// The points of a part's items in the order of the whole study's tables: by the method's family
/// (`family` of its name) in the order of `order` (families not in it after those, in order of
/// first appearance), then by item, then as the item gave them.
fn arrange(
    items: Vec<(usize, Vec<Point>)>,
    order: &[&str],
    family: fn(&str) -> &str,
) -> Vec<Point> {
    let mut others: Vec<String> = Vec::new();
    let mut keyed = Vec::new();
    for (i, points) in items {
        for (at, p) in points.into_iter().enumerate() {
            let f = family(&p.method);
            let rank = match order.iter().position(|o| *o == f) {
                Some(r) => r,
                None => {
                    let r = match others.iter().position(|o| o == f) {
                        Some(r) => r,
                        None => {
                            others.push(f.to_string());
                            others.len() - 1
                        }
                    };
                    order.len() + r
                }
            };
            keyed.push(((rank, i, at), p));
        }
    }
    keyed.sort_by_key(|(key, _)| *key);
    keyed.into_iter().map(|(_, p)| p).collect()
}

/// The chetaev method of a point of the limit: `Dopri5` of `Dopri5 hand-written full`.
fn limit_family(method: &str) -> &str {
    method.split_once(' ').map_or(method, |(m, _)| m)
}

/// Whether the method of a point (`Rodas4`, `Dopri5 (ode_solvers)`, ...) evaluates Jacobians.
fn needs_jacobian(method: &str) -> bool {
    AnyMethod::from_name(limit_family(method), Some(1.0)).is_ok_and(|m| m.info().needs_jacobian)
}

/// Writes every table, diagram and `results.md` of the whole study from its merged part. Returns
/// the summary for stdout.
fn report(study: &Study, whole: &Part, out: &Path) -> Result<String, Box<dyn Error>> {
    let plan = study.plan();
    if plan.len() != whole.total || whole.items.len() != whole.total {
        return Err(format!(
            "the parts hold {} of {} items, the settings define {}",
            whole.items.len(),
            whole.total,
            plan.len()
        )
        .into());
    }
    let mut per_scene: Vec<Vec<(usize, Vec<Point>)>> = vec![Vec::new(); study.scenes.len()];
    let mut limit_items = Vec::new();
    let mut comparisons = Vec::new();
    for ((i, v), item) in whole.items.iter().zip(&plan) {
        let f = Fields::of(v, "item")?;
        if let Item::Overhead(_) = item {
            comparisons.push(comparison_from_json(f.get("comparison")?)?);
            continue;
        }
        let points = f
            .array("points")?
            .iter()
            .map(point_from_json)
            .collect::<Result<Vec<_>, _>>()?;
        match item {
            Item::Scene(s, _) => per_scene[*s].push((*i, points)),
            _ => limit_items.push((*i, points)),
        }
    }

    let config = &study.config;
    let mut machines: Vec<String> = Vec::new();
    let mut elapsed = 0.0;
    for r in &whole.runs {
        let about = Fields::of(&r.about, "shard's measurements")?;
        let m = about.str("machine")?.to_string();
        if !machines.contains(&m) {
            machines.push(m);
        }
        elapsed += about.f64("seconds")?;
    }
    let mut results = String::new();
    let _ = writeln!(
        results,
        "# Work-precision results\n\n{}",
        machines.join("\n")
    );
    let _ = writeln!(
        results,
        "Tolerances {} (rtol = atol unless the scene says otherwise); median of at least {} timed runs \
         (more until {} s, at most {}) after one untimed run; step budget {} per run.\n",
        config
            .tolerances
            .iter()
            .map(|t| format!("{t:e}"))
            .collect::<Vec<_>>()
            .join(", "),
        config.budget.min_repeats,
        config.budget.min_seconds,
        config.budget.max_repeats,
        config.max_steps
    );

    let mut summary = String::new();
    let mut all = Vec::new();
    for (scene, items) in study.scenes.iter().zip(per_scene) {
        let points = arrange(items, &scene_order(), |m| m);
        study_report(scene.as_ref(), &points, out, &mut results)?;
        all.extend(points);
    }
    let limit = arrange(limit_items, &[], limit_family);
    limit_report(&limit, out, &mut results, &mut summary)?;
    overheads_report(&all, &comparisons, out, &mut results, &mut summary)?;

    let skipped = all
        .iter()
        .filter(|p| matches!(p.outcome, PointOutcome::Skipped(_)))
        .count();
    let failed = all
        .iter()
        .filter(|p| matches!(p.outcome, PointOutcome::Failed(_)))
        .count();
    let _ = writeln!(
        results,
        "\n{} configurations: {} measured, {skipped} skipped, {failed} failed. Whole run {elapsed:.0} s.",
        all.len(),
        all.len() - skipped - failed
    );
    std::fs::write(out.join("results.md"), &results)?;
    let shards = if whole.runs.len() > 1 {
        format!(" (summed over {} shards)", whole.runs.len())
    } else {
        String::new()
    };
    let _ = writeln!(
        summary,
        "{} configurations ({skipped} skipped, {failed} failed) in {elapsed:.0} s{shards}",
        all.len(),
    );
    if skipped + failed > 0 {
        let _ = writeln!(summary, "{}", not_measured(&all));
    }
    Ok(summary)
}

/// What was not measured, grouped: the skipped points by their reason (up to its first colon:
/// "invalid option rtol = 1e-14", say), the failed ones by scene and the first words of the
/// failure ("the problem became stiff"), so that a run says which failures are the expected
/// stops of explicit methods on a stiff scene.
fn not_measured(all: &[Point]) -> String {
    let mut groups: std::collections::BTreeMap<String, usize> = Default::default();
    for p in all {
        let key = match &p.outcome {
            PointOutcome::Measured => continue,
            PointOutcome::Skipped(why) => {
                format!("skipped, {}", why.split(':').next().unwrap_or(why))
            }
            PointOutcome::Failed(why) => {
                let cause = why.split(" at t =").next().unwrap_or(why);
                format!("failed on the {} scene, {cause}", p.scene)
            }
        };
        *groups.entry(key).or_default() += 1;
    }
    let parts: Vec<String> = groups.iter().map(|(k, n)| format!("{n} {k}")).collect();
    format!("not measured: {}", parts.join("; "))
}

/// `nproc`, the processor and the compiler, for the report.
fn machine() -> String {
    let cores = std::thread::available_parallelism().map_or(0, |n| n.get());
    let cpu = chetaev_bench::measure::cpu_model();
    let rustc = std::process::Command::new("rustc")
        .arg("--version")
        .output()
        .ok()
        .and_then(|o| String::from_utf8(o.stdout).ok())
        .map_or("unknown".to_string(), |s| s.trim().to_string());
    let build = if cfg!(debug_assertions) {
        "debug"
    } else {
        "release"
    };
    format!("Machine: {cores} cores, {cpu}; {rustc}; {build} build, one thread.\n")
}

/// One line of a work-precision diagram: name, `(seconds, error)` points, style.
type PlotLine = (String, Vec<(f64, f64)>, Style);

/// A work-precision diagram: error against run time, the error defined by `reference` (what the
/// end state is compared with and how its components are scaled) in the note under the title.
fn svg_figure(title: &str, reference: &str, lines: &[PlotLine]) -> Figure {
    let mut fig = Figure::new(title)
        .note(&format!("Error of the end state (q, q̇): {reference}."))
        .x_label("median run time [s]")
        .y_label("end-state error: max_i(|Δq_i| / L_i, |Δq̇_i| / V)")
        .log_x()
        .log_y()
        .size(820.0, 520.0);
    for (name, pts, style) in lines {
        if !pts.is_empty() {
            fig = fig.line_styled(name, pts, *style);
        }
    }
    fig
}

/// `(seconds, error)` of a method's measured points, for plotting.
fn plot_curve(points: &[Point], method: &str) -> Vec<(f64, f64)> {
    curve(points, method)
        .into_iter()
        .map(|(e, s)| (s, e))
        .collect()
}

fn comparison_row(md: &mut String, c: &Comparison) {
    let _ = writeln!(
        md,
        "| {} | {} | {} | {} | {:.2} | {:.2} | {} / {} | {} / {} | {:.1e} |",
        c.what,
        c.setting,
        format_seconds(c.lean_seconds),
        format_seconds(c.costly_seconds),
        c.ratio(),
        c.ratio_per_rhs(),
        c.lean_rhs,
        c.costly_rhs,
        c.lean_output,
        c.costly_output,
        c.end_difference
    );
}

/// A scene's CSV, diagram and Markdown from its points.
fn study_report(
    scene: &dyn AnyScene,
    points: &[Point],
    out: &Path,
    results: &mut String,
) -> Result<(), Box<dyn Error>> {
    let key = scene.key();
    std::fs::write(out.join(format!("{key}.csv")), points_csv(points))?;

    let mut lines = Vec::new();
    for (m, c) in methods() {
        let style = Style {
            color: Some(c),
            markers: true,
            ..Style::default()
        };
        lines.push((m.to_string(), plot_curve(points, m), style));
    }
    for (m, c) in [
        ("Dopri5 (ode_solvers)", "#0072B2"),
        ("Dop853 (ode_solvers)", "#D55E00"),
    ] {
        let style = Style {
            color: Some(c),
            dashed: true,
            markers: true,
            ..Style::default()
        };
        lines.push((m.to_string(), plot_curve(points, m), style));
    }
    svg_figure(scene.title(), scene.reference(), &lines).save(out.join(format!("{key}.svg")))?;

    let pairs = [
        ("Dopri5", "Dopri5 (ode_solvers)"),
        ("Dop853", "Dop853 (ode_solvers)"),
    ];
    let mut md = format!(
        "## {}\n\nError: {}.\n\n![{}]({}.svg)\n\n",
        scene.title(),
        scene.reference(),
        scene.title(),
        key
    );
    md.push_str(&ratio_markdown(points, &pairs, &COMPARE_AT));
    md.push('\n');
    let by_tolerance = ratio_at_tolerance_markdown(points, &pairs);
    if !by_tolerance.is_empty() {
        md.push_str(&by_tolerance);
        md.push('\n');
    }
    md.push_str(&points_markdown(points));
    std::fs::write(out.join(format!("{key}.md")), &md)?;
    results.push_str(&md);
    results.push('\n');
    Ok(())
}

/// chetaev against the hand-written right-hand sides of the paper's model (timed interleaved):
/// CSV, diagrams and Markdown from the points.
fn limit_report(
    points: &[Point],
    out: &Path,
    results: &mut String,
    summary: &mut String,
) -> Result<(), Box<dyn Error>> {
    let (reduced_hw, full_hw) = (scenes::reduced_handwritten(), scenes::full_handwritten());
    let of = |suffix: &str| -> Vec<Point> {
        points
            .iter()
            .filter(|p| p.method.ends_with(suffix))
            .cloned()
            .collect()
    };
    let (reduced, full) = (of(reduced_hw.name), of(full_hw.name));
    std::fs::write(out.join("limit.csv"), points_csv(points))?;

    for (form, suffix, title) in [
        (
            "reduced",
            "hand-written (42.28)",
            "chetaev against the reduced equation (42.28) by hand",
        ),
        (
            "full",
            "hand-written full",
            "chetaev against a = g − (g·v)v/|v|² by hand",
        ),
    ] {
        let mut lines = Vec::new();
        for (m, c) in methods() {
            lines.push((
                format!("{m} (chetaev)"),
                plot_curve(points, m),
                Style {
                    color: Some(c),
                    markers: true,
                    ..Style::default()
                },
            ));
            lines.push((
                format!("{m} {suffix}"),
                plot_curve(points, &format!("{m} {suffix}")),
                Style {
                    color: Some(c),
                    dashed: true,
                    markers: true,
                    ..Style::default()
                },
            ));
        }
        svg_figure(title, scenes::UNIFORM_REFERENCE, &lines)
            .save(out.join(format!("limit-{form}.svg")))?;
    }

    let mut md = String::from(
        "## The limit: the paper's model by hand\n\nchetaev's time over the hand-written system's time at \
         equal error (log time interpolated linearly in log error), same methods, same driver, same \
         end time and error measure as the uniform scene. At every setting the three are timed \
         interleaved (one run of each in turn), so that they see the same background load.\n\n![chetaev against (42.28)](limit-reduced.svg)\n\n\
         ![chetaev against the full form](limit-full.svg)\n\n",
    );
    let mut pairs_owned = Vec::new();
    for (m, _) in methods() {
        pairs_owned.push((m.to_string(), format!("{m} hand-written (42.28)")));
        pairs_owned.push((m.to_string(), format!("{m} hand-written full")));
    }
    let pairs: Vec<(&str, &str)> = pairs_owned
        .iter()
        .map(|(a, b)| (a.as_str(), b.as_str()))
        .collect();
    md.push_str(&ratio_markdown(points, &pairs, &COMPARE_AT));
    md.push_str("\nTime per right-hand side (median over the measured points of time / RHS evaluations; \
                 includes the driver's and the method's own work per stage):\n\n\
                 | method | chetaev | hand-written (42.28) | hand-written full |\n|---|---|---|---|\n");
    for (m, _) in methods() {
        let per = |name: &str| {
            let mut v: Vec<f64> = points
                .iter()
                .filter(|p| p.method == name && p.is_measured() && p.rhs_evaluations > 0)
                .map(|p| p.seconds / p.rhs_evaluations as f64)
                .collect();
            chetaev_bench::measure::median(&mut v)
        };
        let _ = writeln!(
            md,
            "| {m} | {} | {} | {} |",
            format_seconds(per(m)),
            format_seconds(per(&format!("{m} hand-written (42.28)"))),
            format_seconds(per(&format!("{m} hand-written full")))
        );
    }
    md.push_str("\n### Hand-written points\n\n");
    md.push_str(&points_markdown(&reduced));
    md.push('\n');
    md.push_str(&points_markdown(&full));
    std::fs::write(out.join("limit.md"), &md)?;
    results.push_str(&md);
    results.push('\n');

    let _ = writeln!(summary, "chetaev / hand-written at equal error:");
    for (a, b) in &pairs {
        let ratios: Vec<String> = [1e-10, 1e-11, 1e-12, 1e-13]
            .iter()
            .map(|&e| {
                format!(
                    "{e:.0e}: {}",
                    format_ratio(ratio_at_error(&curve(points, a), &curve(points, b), e))
                )
            })
            .collect();
        let _ = writeln!(summary, "  {a} / {b}: {}", ratios.join(", "));
    }
    Ok(())
}

/// Constraints and diagnostics that a problem does not use, and the Jacobians of explicit methods.
fn overheads_report(
    all: &[Point],
    rows: &[Comparison],
    out: &Path,
    results: &mut String,
    summary: &mut String,
) -> Result<(), Box<dyn Error>> {
    let mut md = String::from(
        "## Paying only for what is used\n\nWhole solves of the paper's particle to its impact time \
         (Record::State and output at the end unless said otherwise). Ratio = costly / lean.\n\n\
         | comparison | setting | lean | costly | ratio | ratio per RHS | RHS lean / costly | output evaluations lean / costly | end-state difference |\n\
         |---|---|---|---|---|---|---|---|---|\n",
    );
    for c in rows {
        comparison_row(&mut md, c);
        let _ = writeln!(
            summary,
            "{} ({}): ratio {:.2}",
            c.what,
            c.setting,
            c.ratio()
        );
    }
    let ran: Vec<&Point> = all
        .iter()
        .filter(|p| !matches!(p.outcome, PointOutcome::Skipped(_)))
        .collect();
    let (rodas, explicit): (Vec<&Point>, Vec<&Point>) =
        ran.into_iter().partition(|p| needs_jacobian(&p.method));
    let explicit_jac: usize = explicit.iter().map(|p| p.jacobian_evaluations).sum();
    let rodas_jac: usize = rodas.iter().map(|p| p.jacobian_evaluations).sum();
    let (implicit_names, explicit_names): (Vec<&str>, Vec<&str>) = methods()
        .into_iter()
        .map(|(m, _)| m)
        .partition(|m| needs_jacobian(m));
    let (implicit_names, explicit_names) = (implicit_names.join(", "), explicit_names.join(", "));
    let _ = writeln!(
        md,
        "\nJacobians: the {} runs of explicit methods above ({explicit_names} and ode_solvers, \
         every scene, measured or failed) evaluated {explicit_jac} Jacobians in all \
         (`sol.stats.jacobian_evaluations`); the {} runs of {implicit_names} evaluated \
         {rodas_jac}.",
        explicit.len(),
        rodas.len()
    );
    let _ = writeln!(
        summary,
        "Jacobian evaluations: explicit methods {explicit_jac} over {} runs, {implicit_names} \
         {rodas_jac} over {} runs",
        explicit.len(),
        rodas.len()
    );
    std::fs::write(out.join("overheads.md"), &md)?;
    results.push_str(&md);
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_quick_tolerances_are_all_accepted_by_the_library() {
        let args = Cli::parse_from(["work-precision", "--quick"]).run;
        let settings = Settings::from_args(&args).expect("settings");
        assert_eq!(settings.tolerances.len(), 4);
        for &tol in &settings.tolerances {
            let options = Options::until(1.0).tolerances(tol, tol);
            assert_eq!(options.validate(0.0, 2), Ok(()), "--quick lists {tol:e}");
        }
    }

    /// A study of seconds: two tolerances, two step counts of `Rk4`, one timed run.
    fn tiny() -> Settings {
        Settings {
            tolerances: vec![1e-3, 1e-6],
            rk4_steps: Some(vec![8, 32]),
            budget: Budget {
                min_repeats: 1,
                max_repeats: 1,
                min_seconds: 0.0,
            },
            max_steps: 1000,
        }
    }

    /// The points without their measurements of time.
    fn untimed(points: &[Point]) -> Vec<String> {
        points
            .iter()
            .map(|p| {
                let mut p = p.clone();
                (p.seconds, p.repeats) = (0.0, 0);
                format!("{p:?}")
            })
            .collect()
    }

    #[test]
    fn items_arranged_give_the_points_of_whole_scenes_in_their_order() {
        let settings = tiny();
        let mut study = Study::new(&settings).expect("scenes");
        let plan = study.plan();
        let config = settings.config();
        let mut items = Vec::new();
        for (i, item) in plan.iter().enumerate() {
            if let Item::Scene(0, setting) = item {
                items.push((i, study.scenes[0].run(&config, *setting)));
            }
        }
        let arranged = arrange(items, &scene_order(), |m| m);
        let mut scene = scenes::uniform_scene().expect("scene");
        scene.fixed_steps = Ok(vec![8, 32]);
        let whole = run_scene(&scene, &config, &mut |_| {});
        assert_eq!(untimed(&arranged), untimed(&whole));
        // Every method of the library's list: those with error control and ode_solvers' two at
        // the two tolerances, Rk4 at the two step counts.
        let adaptive = scene_order().len() - 1;
        assert_eq!(whole.len(), adaptive * 2 + 2);
        for name in AnyMethod::NAMES {
            assert!(whole.iter().any(|p| p.method == *name), "{name} is studied");
        }
    }

    #[test]
    fn limit_items_arranged_give_the_points_of_the_whole_limit_in_its_order() {
        let settings = tiny();
        let mut study = Study::new(&settings).expect("scenes");
        let plan = study.plan();
        let mut items = Vec::new();
        for (i, item) in plan.iter().enumerate() {
            if matches!(item, Item::Limit(_)) {
                items.push((i, study.run(*item).expect("runs")));
            }
        }
        let items = items
            .into_iter()
            .map(|(i, v)| {
                let points = v["points"]
                    .as_array()
                    .expect("points")
                    .iter()
                    .map(|p| point_from_json(p).expect("a point"))
                    .collect();
                (i, points)
            })
            .collect();
        let arranged = arrange(items, &[], limit_family);
        let scene = scenes::uniform_scene().expect("scene");
        let (reduced, full) = (scenes::reduced_handwritten(), scenes::full_handwritten());
        let whole = run_limit(&scene, &reduced, &full, &settings.config(), &[8, 32]);
        assert_eq!(untimed(&arranged), untimed(&whole));
        let adaptive = methods().len() - 1;
        assert_eq!(whole.len(), 3 * (adaptive * 2 + 2));
    }

    #[test]
    fn settings_read_back_and_define_the_same_items() {
        let settings = tiny();
        let back = Settings::from_json(&settings.to_json()).expect("reads");
        assert_eq!(back, settings);
        let plan = Study::new(&settings).expect("scenes").plan();
        // Per scene: 2 tolerances and 2 step counts, but the stiff scene refuses Rk4 once; the
        // limit likewise; 6 overheads.
        assert_eq!(plan.len(), 4 * 4 + 3 + 4 + OVERHEADS);
        assert!(plan.contains(&Item::Scene(2, Setting::StepsRefused)));
    }
}
