//! How a variable varies: a list, a grid (linear or logarithmic), or a range sampled at random;
//! and the random samples themselves, reproducible from a seed.

/// Linear or logarithmic spacing.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Scale {
    /// Equal steps of the value.
    Linear,
    /// Equal steps of its logarithm (both ends positive, or both negative).
    Log,
}

impl Scale {
    /// The point a fraction `u ∈ [0, 1]` of the way from `from` to `to`: `u = 1` gives `to`
    /// exactly.
    pub fn at(self, from: f64, to: f64, u: f64) -> f64 {
        if u == 1.0 {
            return to;
        }
        match self {
            Scale::Linear => from + (to - from) * u,
            // Both of one sign (checked when read): the magnitudes are spaced geometrically, by
            // powers of ten so that a grid over decades hits them exactly (1, 10, 100).
            Scale::Log => {
                let (a, b) = (from.abs().log10(), to.abs().log10());
                from.signum() * 10f64.powf(a + (b - a) * u)
            }
        }
    }
}

/// The values of a variable.
#[derive(Clone, Debug, PartialEq)]
pub enum Axis {
    /// A list, or a grid expanded to its values: each is a point of the grid.
    Values(Vec<f64>),
    /// A range sampled at random, [`Sweep::samples`](super::Sweep::samples) times per grid point.
    Random {
        /// One end.
        from: f64,
        /// The other.
        to: f64,
        /// Uniform in the value or in its logarithm.
        scale: Scale,
    },
}

impl Axis {
    /// Whether the axis is sampled at random.
    pub fn is_random(&self) -> bool {
        matches!(self, Axis::Random { .. })
    }

    /// The number of grid values (1 for a random range, which multiplies the samples instead).
    pub fn count(&self) -> usize {
        match self {
            Axis::Values(v) => v.len(),
            Axis::Random { .. } => 1,
        }
    }

    /// The axis in words, for the part files' settings.
    pub fn describe(&self) -> serde_json::Value {
        match self {
            Axis::Values(v) => serde_json::json!({
                "values": v.iter().map(|&x| chetaev_parts::number(x)).collect::<Vec<_>>()
            }),
            Axis::Random { from, to, scale } => serde_json::json!({
                "random": [chetaev_parts::number(*from), chetaev_parts::number(*to)],
                "scale": if *scale == Scale::Log { "log" } else { "linear" },
            }),
        }
    }
}

/// How random ranges are sampled.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Design {
    /// Independent uniform samples.
    Uniform,
    /// A Latin hypercube: each range cut into `samples` equal strata, each stratum sampled once
    /// per variable, the strata of the variables paired at random.
    Latin,
}

impl Design {
    /// `uniform` or `latin`.
    pub fn from_name(name: &str) -> Result<Self, String> {
        match name {
            "uniform" => Ok(Design::Uniform),
            "latin" | "lhs" | "latin-hypercube" => Ok(Design::Latin),
            other => Err(format!(
                "unknown design `{other}`: write \"uniform\" (independent samples) or \"latin\" \
                 (a Latin hypercube)"
            )),
        }
    }

    /// The name read by [`Design::from_name`].
    pub fn name(self) -> &'static str {
        match self {
            Design::Uniform => "uniform",
            Design::Latin => "latin",
        }
    }
}

/// SplitMix64 (Steele, Lea and Flood, "Fast splittable pseudorandom number generators", OOPSLA
/// 2014): fixed by its definition, so a seed gives the same samples on every machine and version.
struct SplitMix64(u64);

impl SplitMix64 {
    fn next(&mut self) -> u64 {
        self.0 = self.0.wrapping_add(0x9e37_79b9_7f4a_7c15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
        z ^ (z >> 31)
    }

    /// Uniform in `[0, 1)`, from the top 53 bits.
    fn unit(&mut self) -> f64 {
        (self.next() >> 11) as f64 * (1.0 / (1u64 << 53) as f64)
    }

    /// Uniform in `0..n` (`n ≥ 1`), without modulo bias (Lemire's method, rejecting the short
    /// range).
    fn below(&mut self, n: u64) -> u64 {
        loop {
            let m = u128::from(self.next()) * u128::from(n);
            let low = m as u64;
            if low >= n.wrapping_neg() % n {
                return (m >> 64) as u64;
            }
        }
    }
}

/// `samples × variables` numbers in `[0, 1)`, row by row (a sample's variables together).
pub(super) fn unit_samples(
    design: Design,
    samples: usize,
    variables: usize,
    seed: u64,
) -> Vec<f64> {
    let mut rng = SplitMix64(seed);
    let mut out = vec![0.0; samples * variables];
    match design {
        Design::Uniform => {
            for x in &mut out {
                *x = rng.unit();
            }
        }
        Design::Latin => {
            let mut strata: Vec<usize> = (0..samples).collect();
            for j in 0..variables {
                // Fisher–Yates: a random pairing of the strata with the samples.
                for i in (1..samples).rev() {
                    let k = rng.below(i as u64 + 1) as usize;
                    strata.swap(i, k);
                }
                for (s, &stratum) in strata.iter().enumerate() {
                    out[s * variables + j] = (stratum as f64 + rng.unit()) / samples as f64;
                }
            }
        }
    }
    out
}

/// Whether a TOML table is a range (`from`, `to`, ...) rather than a table of variables.
pub(super) fn looks_like_range(t: &toml::Table) -> bool {
    t.contains_key("from") || t.contains_key("to")
}

fn toml_number(v: &toml::Value) -> Option<f64> {
    match v {
        toml::Value::Float(x) => Some(*x),
        toml::Value::Integer(i) => Some(*i as f64),
        _ => None,
    }
}

const SHAPES: &str = "a list [1.0, 2.0, 5.0], a grid { from = 1.0, to = 10.0, count = 10 } \
                      (add scale = \"log\" for a logarithmic one), or a range sampled at random \
                      { from = 1.0, to = 10.0 } (with `samples`)";

/// An axis written in TOML.
pub(super) fn axis_from_toml(v: &toml::Value) -> Result<Axis, String> {
    match v {
        toml::Value::Array(items) => {
            let values = items
                .iter()
                .map(|x| {
                    toml_number(x).ok_or_else(|| format!("`{x}` is not a number; give {SHAPES}"))
                })
                .collect::<Result<Vec<f64>, String>>()?;
            list(values)
        }
        toml::Value::Table(t) => {
            for key in t.keys() {
                if !["from", "to", "count", "scale"].contains(&key.as_str()) {
                    return Err(format!(
                        "unknown key `{key}`; a range has from, to, count (for a grid) and scale \
                         (\"linear\" or \"log\")"
                    ));
                }
            }
            let end = |key: &str| -> Result<f64, String> {
                let v = t
                    .get(key)
                    .ok_or_else(|| format!("a range needs `{key}`; give {SHAPES}"))?;
                toml_number(v).ok_or_else(|| format!("`{key}` is not a number"))
            };
            let (from, to) = (end("from")?, end("to")?);
            let scale = match t.get("scale") {
                None => Scale::Linear,
                Some(toml::Value::String(s)) => scale_from_name(s)?,
                Some(other) => {
                    return Err(format!("`scale` is {other}: write \"linear\" or \"log\""))
                }
            };
            let count = match t.get("count") {
                None => None,
                Some(toml::Value::Integer(c)) => Some(*c),
                Some(other) => {
                    return Err(format!("`count` is {other}: give a whole number of values"))
                }
            };
            range(from, to, count, scale)
        }
        other => toml_number(other)
            .map(|x| list(vec![x]))
            .unwrap_or_else(|| {
                Err(format!(
                    "`{other}` is not how a variable varies; give {SHAPES}"
                ))
            }),
    }
}

fn scale_from_name(s: &str) -> Result<Scale, String> {
    match s {
        "linear" => Ok(Scale::Linear),
        "log" => Ok(Scale::Log),
        other => Err(format!(
            "unknown scale `{other}`: write \"linear\" or \"log\""
        )),
    }
}

/// An axis written on the command line: `5:20:4`, `1:100:5:log`, `1,2,5`, `5:20`, `1:100:log`.
pub(super) fn axis_from_text(text: &str) -> Result<Axis, String> {
    let number = |s: &str| -> Result<f64, String> {
        s.trim()
            .parse::<f64>()
            .map_err(|_| format!("`{}` is not a number", s.trim()))
    };
    let text = text.trim();
    if text.contains(':') {
        let mut parts: Vec<&str> = text.split(':').collect();
        let scale = match parts.last().map(|s| s.trim()) {
            Some("log") => {
                parts.pop();
                Scale::Log
            }
            Some("linear") => {
                parts.pop();
                Scale::Linear
            }
            _ => Scale::Linear,
        };
        let count =
            match parts.len() {
                2 => None,
                3 => Some(parts[2].trim().parse::<i64>().map_err(|_| {
                    format!("the count `{}` is not a whole number", parts[2].trim())
                })?),
                _ => return Err(
                    "write FROM:TO:COUNT for a grid, FROM:TO for a range sampled at random, each \
                     with :log for a logarithmic scale, or a list 1,2,5"
                        .to_string(),
                ),
            };
        return range(number(parts[0])?, number(parts[1])?, count, scale);
    }
    let inner = text.trim_start_matches('[').trim_end_matches(']').trim();
    if inner.is_empty() {
        return list(Vec::new());
    }
    let values = inner
        .split(',')
        .map(number)
        .collect::<Result<Vec<f64>, String>>()?;
    list(values)
}

fn list(values: Vec<f64>) -> Result<Axis, String> {
    if values.is_empty() {
        return Err("the list is empty: give at least one value".to_string());
    }
    if let Some(x) = values.iter().find(|x| !x.is_finite()) {
        return Err(format!("the value {x} is not finite"));
    }
    Ok(Axis::Values(values))
}

fn range(from: f64, to: f64, count: Option<i64>, scale: Scale) -> Result<Axis, String> {
    if !from.is_finite() || !to.is_finite() {
        return Err(format!("the range from {from} to {to} is not finite"));
    }
    if scale == Scale::Log && (from * to <= 0.0) {
        return Err(format!(
            "a logarithmic range cannot reach or cross zero, and this one runs from {from} to \
             {to}: give both ends of one sign, or scale = \"linear\""
        ));
    }
    match count {
        None => {
            if from == to {
                return Err(format!(
                    "the range from {from} to {to} is empty: give two different ends, or a list \
                     [{from}] for one value"
                ));
            }
            Ok(Axis::Random { from, to, scale })
        }
        Some(c) if c < 1 => Err(format!("`count` is {c}: give at least 1 value")),
        Some(1) => Ok(Axis::Values(vec![from])),
        Some(c) => {
            if from == to {
                return Err(format!(
                    "the range from {from} to {to} has one value but count = {c}: give two \
                     different ends, or count = 1"
                ));
            }
            let c = usize::try_from(c).map_err(|_| format!("`count` {c} is too large"))?;
            if c > super::MAX_RUNS_UNCONFIRMED {
                return Err(format!(
                    "`count` is {c}, more than {} values on one axis",
                    super::MAX_RUNS_UNCONFIRMED
                ));
            }
            let n = (c - 1) as f64;
            Ok(Axis::Values(
                (0..c).map(|i| scale.at(from, to, i as f64 / n)).collect(),
            ))
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn grids_include_both_ends_and_log_grids_are_geometric() {
        let Axis::Values(v) = axis_from_text("1:100:3:log").expect("valid") else {
            panic!("a grid")
        };
        assert_eq!(v[0], 1.0);
        assert_eq!(v[1], 10.0);
        assert_eq!(v[2], 100.0);
        let Axis::Values(v) = axis_from_text("-1:-100:3:log").expect("valid") else {
            panic!("a grid")
        };
        assert!((v[1] + 10.0).abs() < 1e-14 && v[2] == -100.0);
        assert_eq!(
            axis_from_text("5:20:4").expect("valid"),
            Axis::Values(vec![5.0, 10.0, 15.0, 20.0])
        );
        assert_eq!(
            axis_from_text("1, 2,5").expect("valid"),
            Axis::Values(vec![1.0, 2.0, 5.0])
        );
    }

    #[test]
    fn empty_ranges_and_log_ranges_through_zero_are_refused() {
        for bad in [
            "0:10:5:log",
            "-1:10:log",
            "5:5:3",
            "5:5",
            "1:2:0",
            "1:2:x",
            "",
            "1:2:3:4:5",
        ] {
            assert!(axis_from_text(bad).is_err(), "{bad}");
        }
        let e = axis_from_text("0:10:5:log").expect_err("through zero");
        assert!(e.contains("cannot reach or cross zero"), "{e}");
    }

    #[test]
    fn latin_samples_hit_every_stratum_once_per_variable() {
        let (n, d) = (50, 3);
        let u = unit_samples(Design::Latin, n, d, 7);
        for j in 0..d {
            let mut strata: Vec<usize> =
                (0..n).map(|s| (u[s * d + j] * n as f64) as usize).collect();
            strata.sort_unstable();
            assert_eq!(strata, (0..n).collect::<Vec<_>>());
        }
        // The same seed, the same samples; another seed, others.
        assert_eq!(u, unit_samples(Design::Latin, n, d, 7));
        assert_ne!(u, unit_samples(Design::Latin, n, d, 8));
    }

    #[test]
    fn uniform_samples_have_the_mean_and_spread_of_the_uniform_law() {
        let u = unit_samples(Design::Uniform, 100_000, 1, 1);
        let mean = u.iter().sum::<f64>() / u.len() as f64;
        let var = u.iter().map(|x| (x - mean).powi(2)).sum::<f64>() / u.len() as f64;
        // Standard errors: 1/sqrt(12 n) ≈ 9e-4 for the mean; five of them.
        assert!((mean - 0.5).abs() < 5e-3, "{mean}");
        assert!((var - 1.0 / 12.0).abs() < 2e-3, "{var}");
        assert!(u.iter().all(|&x| (0.0..1.0).contains(&x)));
    }

    #[test]
    fn splitmix64_gives_its_published_sequence() {
        // The first outputs for seed 1234567 of the reference implementation
        // (Vigna, splitmix64.c).
        let mut r = SplitMix64(1_234_567);
        assert_eq!(r.next(), 6_457_827_717_110_365_317);
        assert_eq!(r.next(), 3_203_168_211_198_807_973);
    }
}
