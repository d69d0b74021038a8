//! Sweeps split into shards, and the parts they write joined again: one convention for every
//! sweep of the project (`chetaev sweep`, and the ensemble and work-precision binaries).
//!
//! A sweep is a list of items numbered `0..total` (the points of a scene's sweep, the grid points
//! of the ensemble, the settings of the work-precision study). Shard `k/n`, with `k` counted from 1 (`1 ≤ k ≤ n`, as in Slurm's
//! `--array=1-n`), owns the items
//!
//! ```text
//! i  with  i mod n = k − 1,
//! ```
//!
//! so that neighbouring items, which tend to cost alike, go to different shards. Each shard writes
//! a [`Part`]: the sweep's settings, the results of its items by index, and what it measured about
//! itself (machine, run time). [`merge`] checks that the parts belong to one sweep and cover every
//! shard and every item exactly once, and returns one part holding them all, from which a binary
//! writes the same files as the run of the whole sweep. The run of the whole sweep is shard `1/1`.
//!
//! The file is JSON. Numbers are written in the shortest form that reads back to the same `f64`;
//! NaN and the infinities, which JSON lacks, are the strings `"NaN"`, `"inf"`, `"-inf"`.
//! Measurements of time (the fields ending in `seconds`, the `repeats` they took and each shard's
//! `about`) differ from run to run; everything else is a function of the settings.

use std::error::Error;
use std::fmt;
use std::path::{Path, PathBuf};
use std::str::FromStr;

use serde_json::{json, Map, Value};

/// The tag of the file format, checked on reading.
pub const FORMAT: &str = "chetaev part 1";

/// The tag of the same format as it was first written, read as [`FORMAT`].
const FORMAT_FIRST: &str = "chetaev-bench part 1";

/// Everything that can be wrong with a shard or with the parts of a sweep.
#[derive(Clone, Debug, PartialEq)]
#[non_exhaustive]
pub enum PartError {
    /// A shard that is not `k/n` with `1 ≤ k ≤ n`.
    BadShard {
        /// What was given.
        given: String,
    },
    /// A part file that does not have the layout of [`Part`].
    Malformed {
        /// What is missing or of the wrong kind.
        what: String,
    },
    /// Parts of different sweeps, or of the same sweep split differently.
    Mismatch {
        /// What differs.
        what: String,
    },
    /// Nothing to merge.
    NoParts,
    /// A shard given twice.
    DuplicateShard {
        /// The shard.
        shard: Shard,
    },
    /// Shards absent from the parts.
    MissingShards {
        /// The absent `k`, ascending.
        missing: Vec<usize>,
        /// The number of shards.
        n: usize,
    },
    /// An item given twice.
    DuplicateItem {
        /// Its index.
        index: usize,
    },
    /// Items absent although all shards are there.
    MissingItems {
        /// The first absent indices.
        first: Vec<usize>,
        /// How many are absent.
        count: usize,
    },
}

impl fmt::Display for PartError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Self::BadShard { given } => write!(
                f,
                "shard `{given}` is not k/n with 1 ≤ k ≤ n (shards count from 1, as \
                 `--array=1-n` does; for an index i counted from 0 pass `$((i + 1))/n`)"
            ),
            Self::Malformed { what } => write!(f, "not a part file of this program: {what}"),
            Self::Mismatch { what } => write!(
                f,
                "the parts belong to different sweeps: {what} (merge the parts of one run only, \
                 all made with the same options)"
            ),
            Self::NoParts => f.write_str("no part files given"),
            Self::DuplicateShard { shard } => write!(
                f,
                "shard {shard} is given twice (a merged file already holds all its shards; pass \
                 it alone, or only the parts)"
            ),
            Self::MissingShards { missing, n } => {
                let list: Vec<String> = missing.iter().map(ToString::to_string).collect();
                write!(
                    f,
                    "shard(s) {} of {n} missing: run them with `--shard k/{n}` and merge again",
                    list.join(", ")
                )
            }
            Self::DuplicateItem { index } => write!(f, "item {index} is given twice"),
            Self::MissingItems { first, count } => write!(
                f,
                "{count} item(s) missing although every shard is present (the first: {first:?}); \
                 the part files are incomplete, run their shards again"
            ),
        }
    }
}

impl std::error::Error for PartError {}

/// A [`PartError::Malformed`] saying `what` is missing or of the wrong kind.
pub fn malformed(what: impl Into<String>) -> PartError {
    PartError::Malformed { what: what.into() }
}

/// Shard `k` of `n`, `1 ≤ k ≤ n`: the items `i` with `i mod n = k − 1`.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub struct Shard {
    k: usize,
    n: usize,
}

impl Shard {
    /// The whole sweep, `1/1`.
    pub const WHOLE: Self = Self { k: 1, n: 1 };

    /// Shard `k` of `n`; an error unless `1 ≤ k ≤ n`.
    pub fn new(k: usize, n: usize) -> Result<Self, PartError> {
        if k == 0 || k > n {
            return Err(PartError::BadShard {
                given: format!("{k}/{n}"),
            });
        }
        Ok(Self { k, n })
    }

    /// Which shard, from 1.
    pub fn k(self) -> usize {
        self.k
    }

    /// How many shards.
    pub fn n(self) -> usize {
        self.n
    }

    /// Whether item `i` belongs to this shard: `i mod n = k − 1`.
    pub fn owns(self, i: usize) -> bool {
        i % self.n == self.k - 1
    }

    /// The indices of this shard's items among `0..total`, ascending.
    pub fn items(self, total: usize) -> impl Iterator<Item = usize> {
        (self.k - 1..total).step_by(self.n)
    }
}

impl fmt::Display for Shard {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{}/{}", self.k, self.n)
    }
}

impl FromStr for Shard {
    type Err = PartError;

    /// `k/n`, for example `3/8`.
    fn from_str(s: &str) -> Result<Self, Self::Err> {
        let bad = || PartError::BadShard {
            given: s.to_string(),
        };
        let (k, n) = s.trim().split_once('/').ok_or_else(bad)?;
        let k = k.trim().parse().map_err(|_| bad())?;
        let n = n.trim().parse().map_err(|_| bad())?;
        Self::new(k, n).map_err(|_| bad())
    }
}

/// What one shard recorded about its run.
#[derive(Clone, Debug, PartialEq)]
pub struct ShardRun {
    /// The shard.
    pub shard: Shard,
    /// Measurements and provenance (machine, run times), as the binary chooses.
    pub about: Value,
}

/// The results of some or all shards of a sweep.
#[derive(Clone, Debug, PartialEq)]
pub struct Part {
    /// Which program's sweep (`ensemble`, `work-precision`).
    pub sweep: String,
    /// The settings that define the items; equal in all parts of one sweep.
    pub settings: Value,
    /// The number of items of the whole sweep.
    pub total: usize,
    /// The shards whose items this part holds, ascending.
    pub runs: Vec<ShardRun>,
    /// `(index, result)` of the items, ascending by index.
    pub items: Vec<(usize, Value)>,
}

impl Part {
    /// The results of shard `shard` of a sweep: `items` are `(index, result)` of the items it owns.
    pub fn new(
        sweep: &str,
        settings: Value,
        total: usize,
        shard: Shard,
        about: Value,
        items: Vec<(usize, Value)>,
    ) -> Self {
        Self {
            sweep: sweep.to_string(),
            settings,
            total,
            runs: vec![ShardRun { shard, about }],
            items,
        }
    }

    /// The file name of this part: `<sweep>.json` for a whole sweep or a merge,
    /// `<sweep>.part-<k>-of-<n>.json` for one shard.
    pub fn file_name(&self) -> String {
        match self.runs.as_slice() {
            [run] if run.shard.n > 1 => {
                format!(
                    "{}.part-{}-of-{}.json",
                    self.sweep, run.shard.k, run.shard.n
                )
            }
            _ => format!("{}.json", self.sweep),
        }
    }

    /// Writes the part into the folder `dir`, as [`Part::file_name`].
    pub fn write_into(&self, dir: &Path) -> Result<(), Box<dyn Error>> {
        let path = dir.join(self.file_name());
        std::fs::write(&path, self.to_json())
            .map_err(|e| format!("cannot write {}: {e}", path.display()))?;
        Ok(())
    }

    /// Reads the part files `files` and joins them ([`merge`]) into the whole of the sweep
    /// `sweep`; an error names the file it is about.
    pub fn read_merged(files: &[PathBuf], sweep: &str) -> Result<Self, Box<dyn Error>> {
        let mut parts = Vec::new();
        for f in files {
            let text = std::fs::read_to_string(f)
                .map_err(|e| format!("cannot read {}: {e}", f.display()))?;
            parts.push(Part::from_json(&text).map_err(|e| format!("{}: {e}", f.display()))?);
        }
        let whole = merge(parts)?;
        if whole.sweep != sweep {
            return Err(format!("a part of `{}`, not of `{sweep}`", whole.sweep).into());
        }
        Ok(whole)
    }

    /// The part as pretty-printed JSON.
    pub fn to_json(&self) -> String {
        let runs: Vec<Value> = self
            .runs
            .iter()
            .map(|r| json!({ "shard": r.shard.to_string(), "about": r.about }))
            .collect();
        let items: Vec<Value> = self
            .items
            .iter()
            .map(|(i, v)| json!({ "index": i, "result": v }))
            .collect();
        let v = json!({
            "format": FORMAT,
            "sweep": self.sweep,
            "settings": self.settings,
            "items_total": self.total,
            "shards": runs,
            "items": items,
        });
        let mut s = serde_json::to_string_pretty(&v).unwrap_or_else(|_| v.to_string());
        s.push('\n');
        s
    }

    /// Reads a part written by [`Part::to_json`].
    pub fn from_json(text: &str) -> Result<Self, PartError> {
        let v: Value = serde_json::from_str(text).map_err(|e| malformed(e.to_string()))?;
        let f = Fields::of(&v, "part")?;
        if ![FORMAT, FORMAT_FIRST].contains(&f.str("format")?) {
            return Err(malformed(format!(
                "format `{}`, expected `{FORMAT}`",
                f.str("format")?
            )));
        }
        let runs = f
            .array("shards")?
            .iter()
            .map(|r| {
                let r = Fields::of(r, "shard")?;
                Ok(ShardRun {
                    shard: r.str("shard")?.parse()?,
                    about: r.get("about")?.clone(),
                })
            })
            .collect::<Result<Vec<_>, PartError>>()?;
        if runs.is_empty() {
            return Err(malformed("no shards"));
        }
        let items = f
            .array("items")?
            .iter()
            .map(|i| {
                let i = Fields::of(i, "item")?;
                Ok((i.usize("index")?, i.get("result")?.clone()))
            })
            .collect::<Result<Vec<_>, PartError>>()?;
        Ok(Self {
            sweep: f.str("sweep")?.to_string(),
            settings: f.get("settings")?.clone(),
            total: f.usize("items_total")?,
            runs,
            items,
        })
    }
}

/// Joins parts of one sweep into one part holding every shard and every item, ordered by shard
/// and by index. Fails unless all parts have the same sweep, settings, number of items and number
/// of shards, every shard `1..=n` appears exactly once, every item appears exactly once and in a
/// part of the shard that owns it.
pub fn merge(parts: Vec<Part>) -> Result<Part, PartError> {
    let first = parts.first().ok_or(PartError::NoParts)?;
    let n = first
        .runs
        .first()
        .ok_or_else(|| malformed("a part without shards"))?
        .shard
        .n;
    let (sweep, settings, total) = (first.sweep.clone(), first.settings.clone(), first.total);
    let mut shards: Vec<Option<ShardRun>> = vec![None; n];
    let mut slots: Vec<Option<Value>> = vec![None; total];
    for part in parts {
        if part.sweep != sweep {
            return Err(PartError::Mismatch {
                what: format!("a part of `{}` and one of `{sweep}`", part.sweep),
            });
        }
        if part.settings != settings {
            return Err(PartError::Mismatch {
                what: format!("settings {} and {settings}", part.settings),
            });
        }
        if part.total != total {
            return Err(PartError::Mismatch {
                what: format!("{} items and {total}", part.total),
            });
        }
        for run in &part.runs {
            if run.shard.n != n {
                return Err(PartError::Mismatch {
                    what: format!("shard {} and a split into {n}", run.shard),
                });
            }
        }
        // A shard given twice is named as such, before its first item is found twice.
        if let Some(run) = part.runs.iter().find(|r| shards[r.shard.k - 1].is_some()) {
            return Err(PartError::DuplicateShard { shard: run.shard });
        }
        for (index, result) in part.items {
            if index >= total {
                return Err(malformed(format!("item {index} of a sweep of {total}")));
            }
            if !part.runs.iter().any(|r| r.shard.owns(index)) {
                return Err(malformed(format!(
                    "item {index} in a part of shard(s) that do not own it"
                )));
            }
            if slots[index].replace(result).is_some() {
                return Err(PartError::DuplicateItem { index });
            }
        }
        for run in part.runs {
            let shard = run.shard;
            if shards[shard.k - 1].replace(run).is_some() {
                return Err(PartError::DuplicateShard { shard });
            }
        }
    }
    let missing: Vec<usize> = (1..=n).filter(|k| shards[k - 1].is_none()).collect();
    if !missing.is_empty() {
        return Err(PartError::MissingShards { missing, n });
    }
    let absent: Vec<usize> = (0..total).filter(|&i| slots[i].is_none()).collect();
    if !absent.is_empty() {
        return Err(PartError::MissingItems {
            first: absent.iter().take(5).copied().collect(),
            count: absent.len(),
        });
    }
    Ok(Part {
        sweep,
        settings,
        total,
        runs: shards.into_iter().flatten().collect(),
        items: slots.into_iter().flatten().enumerate().collect(),
    })
}

/// An `f64` as JSON: a number when finite, else `"NaN"`, `"inf"` or `"-inf"`.
pub fn number(x: f64) -> Value {
    if x.is_finite() {
        json!(x)
    } else if x.is_nan() {
        json!("NaN")
    } else if x > 0.0 {
        json!("inf")
    } else {
        json!("-inf")
    }
}

/// An `f64` written by [`number`], `None` if `v` is none.
pub fn read_number(v: &Value) -> Option<f64> {
    match v {
        Value::Number(x) => x.as_f64(),
        Value::String(s) if s == "NaN" => Some(f64::NAN),
        Value::String(s) if s == "inf" => Some(f64::INFINITY),
        Value::String(s) if s == "-inf" => Some(f64::NEG_INFINITY),
        _ => None,
    }
}

/// The fields of a JSON object, read with errors that name the object and the field.
#[derive(Clone, Copy, Debug)]
pub struct Fields<'a> {
    map: &'a Map<String, Value>,
    what: &'a str,
}

impl<'a> Fields<'a> {
    /// The object `v`, called `what` in errors.
    pub fn of(v: &'a Value, what: &'a str) -> Result<Self, PartError> {
        v.as_object()
            .map(|map| Self { map, what })
            .ok_or_else(|| malformed(format!("{what} is not an object")))
    }

    /// The field `key`.
    pub fn get(&self, key: &str) -> Result<&'a Value, PartError> {
        self.map
            .get(key)
            .ok_or_else(|| malformed(format!("{} has no `{key}`", self.what)))
    }

    fn wrong(&self, key: &str, kind: &str) -> PartError {
        malformed(format!("`{key}` of {} is not {kind}", self.what))
    }

    /// A number written by [`number`].
    pub fn f64(&self, key: &str) -> Result<f64, PartError> {
        read_number(self.get(key)?).ok_or_else(|| self.wrong(key, "a number"))
    }

    /// A count.
    pub fn usize(&self, key: &str) -> Result<usize, PartError> {
        self.get(key)?
            .as_u64()
            .and_then(|x| usize::try_from(x).ok())
            .ok_or_else(|| self.wrong(key, "a count"))
    }

    /// A string.
    pub fn str(&self, key: &str) -> Result<&'a str, PartError> {
        self.get(key)?
            .as_str()
            .ok_or_else(|| self.wrong(key, "a string"))
    }

    /// An array.
    pub fn array(&self, key: &str) -> Result<&'a Vec<Value>, PartError> {
        self.get(key)?
            .as_array()
            .ok_or_else(|| self.wrong(key, "an array"))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn shards_count_from_one_and_partition_by_remainder() {
        let s: Shard = "3/8".parse().expect("valid");
        assert_eq!((s.k(), s.n()), (3, 8));
        assert_eq!(s.to_string(), "3/8");
        assert_eq!(s.items(20).collect::<Vec<_>>(), vec![2, 10, 18]);
        assert!(s.owns(2) && s.owns(10) && !s.owns(3));
        for bad in ["0/8", "9/8", "1/0", "3", "a/8", "3/8/1", ""] {
            assert!(
                matches!(bad.parse::<Shard>(), Err(PartError::BadShard { .. })),
                "{bad}"
            );
        }
        // Every item in exactly one shard.
        let n = 3;
        for i in 0..17 {
            let owners = (1..=n)
                .filter(|&k| Shard::new(k, n).expect("valid").owns(i))
                .count();
            assert_eq!(owners, 1);
        }
    }

    #[test]
    fn numbers_read_back_bit_for_bit() {
        let mut xs = vec![
            0.1 + 0.2,
            1.0 / 3.0,
            -0.0,
            5e-324,
            f64::MAX,
            f64::MIN_POSITIVE,
            f64::from_bits(0x000f_ffff_ffff_ffff), // the largest subnormal
            f64::from_bits(0x4340_0000_0000_0001), // 2^53 + 2
            f64::NAN,
            f64::INFINITY,
            f64::NEG_INFINITY,
        ];
        let mut x = 0.123_456_789_f64;
        for _ in 0..2000 {
            x = (x * 1e3).sin().abs() * 10f64.powi((x * 1e6) as i32 % 40 - 20);
            xs.push(x);
        }
        for x in xs {
            let text = serde_json::to_string(&json!({ "x": number(x) })).expect("serialises");
            let v: Value = serde_json::from_str(&text).expect("parses");
            let y = Fields::of(&v, "test")
                .and_then(|f| f.f64("x"))
                .expect("a number");
            assert!(
                x.to_bits() == y.to_bits() || (x.is_nan() && y.is_nan()),
                "{x:e} read back as {y:e} from {text}"
            );
        }
    }

    fn part(shard: &str, total: usize) -> Part {
        let shard: Shard = shard.parse().expect("valid");
        let items = shard.items(total).map(|i| (i, json!(i * i))).collect();
        Part::new(
            "demo",
            json!({ "n": total }),
            total,
            shard,
            json!({ "seconds": 1.0 }),
            items,
        )
    }

    #[test]
    fn parts_merge_into_the_whole_in_any_order() {
        let whole = merge(vec![part("1/1", 10)]).expect("merges");
        let merged = merge(vec![part("3/3", 10), part("1/3", 10), part("2/3", 10)]).expect("ok");
        assert_eq!(merged.items, whole.items);
        assert_eq!(
            merged.runs.iter().map(|r| r.shard.k()).collect::<Vec<_>>(),
            vec![1, 2, 3]
        );
        // A merged file reads back and merges again to itself.
        let text = merged.to_json();
        let again = merge(vec![Part::from_json(&text).expect("reads")]).expect("merges");
        assert_eq!(again, merged);
        assert_eq!(part("2/3", 10).file_name(), "demo.part-2-of-3.json");
        assert_eq!(merged.file_name(), "demo.json");
    }

    #[test]
    fn part_files_are_written_read_and_checked_against_their_sweep() -> Result<(), Box<dyn Error>> {
        let dir = std::env::temp_dir().join(format!("chetaev-parts-{}", std::process::id()));
        std::fs::create_dir_all(&dir)?;
        let files: Vec<PathBuf> = ["1/2", "2/2"]
            .iter()
            .map(|k| {
                let p = part(k, 10);
                p.write_into(&dir).map(|()| dir.join(p.file_name()))
            })
            .collect::<Result<_, _>>()?;
        assert_eq!(
            Part::read_merged(&files, "demo")?,
            merge(vec![part("1/2", 10), part("2/2", 10)])?
        );
        let e = Part::read_merged(&files, "ensemble").expect_err("another sweep");
        assert_eq!(e.to_string(), "a part of `demo`, not of `ensemble`");
        let missing = dir.join("absent.json");
        let e = Part::read_merged(std::slice::from_ref(&missing), "demo").expect_err("no file");
        assert!(
            e.to_string()
                .starts_with(&format!("cannot read {}", missing.display())),
            "{e}"
        );
        std::fs::write(&files[1], "{}")?;
        let e = Part::read_merged(&files, "demo").expect_err("not a part");
        assert!(
            e.to_string()
                .starts_with(&format!("{}: ", files[1].display())),
            "{e}"
        );
        std::fs::remove_dir_all(&dir)?;
        Ok(())
    }

    #[test]
    fn incomplete_or_foreign_parts_are_refused() {
        assert_eq!(merge(Vec::new()), Err(PartError::NoParts));
        assert_eq!(
            merge(vec![part("1/3", 10), part("3/3", 10)]),
            Err(PartError::MissingShards {
                missing: vec![2],
                n: 3
            })
        );
        assert!(matches!(
            merge(vec![part("1/2", 10), part("1/2", 10), part("2/2", 10)]),
            Err(PartError::DuplicateShard { .. })
        ));
        assert!(matches!(
            merge(vec![part("1/2", 10), part("2/2", 11)]),
            Err(PartError::Mismatch { .. })
        ));
        assert!(matches!(
            merge(vec![part("1/2", 10), part("2/3", 10)]),
            Err(PartError::Mismatch { .. })
        ));
        let mut thin = part("2/2", 10);
        thin.items.pop();
        assert_eq!(
            merge(vec![part("1/2", 10), thin]),
            Err(PartError::MissingItems {
                first: vec![9],
                count: 1
            })
        );
        let mut stray = part("2/2", 10);
        stray.items.push((0, json!(0)));
        assert!(matches!(
            merge(vec![stray]),
            Err(PartError::Malformed { .. })
        ));
        assert!(matches!(
            Part::from_json("{\"format\": \"something else\"}"),
            Err(PartError::Malformed { .. })
        ));
    }
}
