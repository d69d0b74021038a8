//! The scene file as written: the serde structures TOML is read into, every value with its span.
//!
//! Nothing here checks more than types and key names (every table rejects unknown keys); what the
//! values mean is checked in [`validate`](super::validate).

use std::collections::BTreeMap;
use std::fmt;

use serde::de::{self, Deserializer, MapAccess, SeqAccess, Visitor};
use serde::Deserialize;
use toml::Spanned;

use super::spec::{Picture, Table};

#[derive(Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub(crate) struct RawScene {
    pub(crate) scene: Option<RawMeta>,
    #[serde(default)]
    pub(crate) parameters: BTreeMap<Spanned<String>, Spanned<Number>>,
    pub(crate) model: Spanned<RawModel>,
    pub(crate) initial: Spanned<RawInitial>,
    pub(crate) solve: Spanned<RawSolve>,
    #[serde(default)]
    pub(crate) loads: Vec<Spanned<RawLoad>>,
    #[serde(default)]
    pub(crate) events: Vec<Spanned<RawEvent>>,
    pub(crate) sensitivities: Option<Spanned<RawSensitivities>>,
    pub(crate) output: Option<RawOutput>,
    /// `[sweep]`: read by [`crate::sweep`], not by the scene itself.
    pub(crate) sweep: Option<Spanned<RawSweep>>,
}

/// `[sweep]`: the variables to vary and the quantities to collect (docs/sweeps.md).
#[derive(Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub(crate) struct RawSweep {
    /// `[sweep.vary]`: a variable (a parameter, `initial.x`, `initial.x_dot`) and how it varies;
    /// each value is read by [`crate::sweep`], which locates its mistakes at the value.
    #[serde(default)]
    pub(crate) vary: BTreeMap<Spanned<String>, Spanned<toml::Value>>,
    /// Random samples of the ranges without `count`.
    pub(crate) samples: Option<Spanned<i64>>,
    /// The seed of the random samples.
    pub(crate) seed: Option<Spanned<i64>>,
    /// `"uniform"` (the default) or `"latin"`.
    pub(crate) design: Option<Spanned<String>>,
    /// The quantities to collect from each run.
    pub(crate) collect: Option<Spanned<Vec<Spanned<String>>>>,
}

/// `[sensitivities]`: the parameters to differentiate the motion with respect to.
#[derive(Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub(crate) struct RawSensitivities {
    pub(crate) parameters: Spanned<Vec<Spanned<String>>>,
    /// Error control on the sensitivities too.
    pub(crate) control: Option<Spanned<bool>>,
}

#[derive(Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub(crate) struct RawMeta {
    pub(crate) name: Option<String>,
    pub(crate) description: Option<String>,
}

#[derive(Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub(crate) struct RawModel {
    pub(crate) coordinates: Spanned<Vec<Spanned<String>>>,
    pub(crate) lagrangian: Spanned<String>,
    pub(crate) constraints: Option<Spanned<Vec<Spanned<String>>>>,
    pub(crate) forces: Option<Spanned<Vec<Spanned<String>>>>,
    pub(crate) holonomic: Option<Spanned<Vec<Spanned<String>>>>,
    pub(crate) dissipation: Option<Spanned<String>>,
    /// Units for the pictures' labels: `t`, coordinate names, `coordinates`, `mu`, `mu_a`, `energy`.
    pub(crate) units: Option<Spanned<BTreeMap<Spanned<String>, Spanned<String>>>>,
}

#[derive(Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub(crate) struct RawInitial {
    pub(crate) t: Option<Spanned<Number>>,
    pub(crate) q: Spanned<Vec<Spanned<Number>>>,
    pub(crate) q_dot: Spanned<Vec<Spanned<Number>>>,
    #[serde(default)]
    pub(crate) project_velocity: bool,
    /// Coordinates held while the others are solved from the holonomic constraints.
    pub(crate) independent_coordinates: Option<Spanned<Vec<Spanned<String>>>>,
    /// Speeds held while the others are solved from the velocity constraints and `ḣ = 0`.
    pub(crate) independent_speeds: Option<Spanned<Vec<Spanned<String>>>>,
}

#[derive(Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub(crate) struct RawSolve {
    pub(crate) method: Option<Spanned<String>>,
    pub(crate) t_end: Spanned<Number>,
    pub(crate) rtol: Option<Spanned<f64>>,
    pub(crate) atol: Option<Spanned<RawAtol>>,
    pub(crate) step: Option<Spanned<Number>>,
    pub(crate) initial_step: Option<Spanned<Number>>,
    pub(crate) max_step: Option<Spanned<Number>>,
    pub(crate) max_steps: Option<Spanned<i64>>,
    #[serde(default)]
    pub(crate) projection: bool,
    pub(crate) stiffness_detection: Option<Spanned<bool>>,
}

/// `[[loads]]`: a force on a point (`point`, `force`) or a torque on a body
/// (`angular_velocity`, `torque`); which pairs are given is checked in validation.
#[derive(Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub(crate) struct RawLoad {
    pub(crate) point: Option<Spanned<Vec<Spanned<String>>>>,
    pub(crate) force: Option<Spanned<Vec<Spanned<String>>>>,
    pub(crate) angular_velocity: Option<Spanned<Vec<Spanned<String>>>>,
    pub(crate) torque: Option<Spanned<Vec<Spanned<String>>>>,
}

#[derive(Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub(crate) struct RawEvent {
    pub(crate) name: Spanned<String>,
    pub(crate) expression: Spanned<String>,
    pub(crate) direction: Option<RawDirection>,
    #[serde(default)]
    pub(crate) terminal: bool,
}

#[derive(Clone, Copy, Debug, Deserialize)]
#[serde(rename_all = "lowercase")]
pub(crate) enum RawDirection {
    Either,
    Rising,
    Falling,
}

#[derive(Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub(crate) struct RawOutput {
    pub(crate) directory: Option<String>,
    pub(crate) times: Option<Spanned<RawTimes>>,
    #[serde(default)]
    pub(crate) tables: Vec<Spanned<Table>>,
    #[serde(default)]
    pub(crate) pictures: Vec<Spanned<Picture>>,
    #[serde(default)]
    pub(crate) quantities: BTreeMap<Spanned<String>, Spanned<String>>,
    /// Units of the output quantities, by name.
    #[serde(default)]
    pub(crate) units: BTreeMap<Spanned<String>, Spanned<String>>,
    /// The panels of the trajectory picture.
    pub(crate) trajectory: Option<Spanned<RawTrajectory>>,
}

/// `output.trajectory`: a list of panels, each a pair of coordinate names `["x", "y"]` or a list of
/// such pairs drawn together `[["x1", "y1"], ["x2", "y2"]]`. Only the whole list keeps its place in
/// the file; a name is found in it by its text.
#[derive(Clone)]
pub(crate) struct RawTrajectory(pub(crate) Vec<Vec<Vec<String>>>);

/// One element of a panel: a name, or a list of names.
enum NameOrList {
    Name(String),
    List(Vec<String>),
}

const PANEL_SHAPE: &str =
    "a pair of coordinate names such as [\"x\", \"y\"], or a list of pairs drawn \
                           together such as [[\"x1\", \"y1\"], [\"x2\", \"y2\"]]";

impl<'de> Deserialize<'de> for NameOrList {
    fn deserialize<D: Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        struct V;
        impl<'de> Visitor<'de> for V {
            type Value = NameOrList;
            fn expecting(&self, f: &mut fmt::Formatter) -> fmt::Result {
                f.write_str("a coordinate name, or a pair of them")
            }
            fn visit_str<E: de::Error>(self, v: &str) -> Result<NameOrList, E> {
                Ok(NameOrList::Name(v.to_string()))
            }
            fn visit_seq<A: SeqAccess<'de>>(self, mut seq: A) -> Result<NameOrList, A::Error> {
                let mut v = Vec::new();
                while let Some(x) = seq.next_element::<String>()? {
                    v.push(x);
                }
                Ok(NameOrList::List(v))
            }
        }
        d.deserialize_any(V)
    }
}

/// One panel: `["x", "y"]` (one pair) or `[["x1", "y1"], ...]` (pairs).
struct RawPanel(Vec<Vec<String>>);

impl<'de> Deserialize<'de> for RawPanel {
    fn deserialize<D: Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        struct V;
        impl<'de> Visitor<'de> for V {
            type Value = RawPanel;
            fn expecting(&self, f: &mut fmt::Formatter) -> fmt::Result {
                f.write_str(PANEL_SHAPE)
            }
            fn visit_str<E: de::Error>(self, v: &str) -> Result<RawPanel, E> {
                Err(E::custom(format!(
                    "\"{v}\" alone is not a panel of the trajectory: each panel is {PANEL_SHAPE}, as in \
                     trajectory = [[\"x\", \"y\"], [\"x\", \"z\"]]"
                )))
            }
            fn visit_seq<A: SeqAccess<'de>>(self, mut seq: A) -> Result<RawPanel, A::Error> {
                let mut names = Vec::new();
                let mut pairs = Vec::new();
                while let Some(x) = seq.next_element::<NameOrList>()? {
                    match x {
                        NameOrList::Name(n) => names.push(n),
                        NameOrList::List(p) => pairs.push(p),
                    }
                }
                match (names.is_empty(), pairs.is_empty()) {
                    (_, true) => Ok(RawPanel(vec![names])),
                    (true, false) => Ok(RawPanel(pairs)),
                    (false, false) => Err(de::Error::custom(format!(
                        "a panel of the trajectory mixes names and lists: it is {PANEL_SHAPE}"
                    ))),
                }
            }
        }
        d.deserialize_any(V)
    }
}

impl<'de> Deserialize<'de> for RawTrajectory {
    fn deserialize<D: Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        struct V;
        impl<'de> Visitor<'de> for V {
            type Value = RawTrajectory;
            fn expecting(&self, f: &mut fmt::Formatter) -> fmt::Result {
                write!(
                    f,
                    "a list of panels, each {PANEL_SHAPE}, as in trajectory = [[\"x\", \"y\"], [\"x\", \"z\"]]"
                )
            }
            fn visit_seq<A: SeqAccess<'de>>(self, mut seq: A) -> Result<RawTrajectory, A::Error> {
                let mut panels = Vec::new();
                while let Some(p) = seq.next_element::<RawPanel>()? {
                    panels.push(p.0);
                }
                Ok(RawTrajectory(panels))
            }
        }
        d.deserialize_any(V)
    }
}

/// A number, or an expression of the parameters in quotes.
#[derive(Clone, Debug)]
pub(crate) enum Number {
    Value(f64),
    Expr(String),
}

impl<'de> Deserialize<'de> for Number {
    fn deserialize<D: Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        struct V;
        impl Visitor<'_> for V {
            type Value = Number;
            fn expecting(&self, f: &mut fmt::Formatter) -> fmt::Result {
                f.write_str("a number or an expression in quotes, such as 5.0 or \"2*h0\"")
            }
            fn visit_f64<E: de::Error>(self, v: f64) -> Result<Number, E> {
                Ok(Number::Value(v))
            }
            fn visit_i64<E: de::Error>(self, v: i64) -> Result<Number, E> {
                Ok(Number::Value(v as f64))
            }
            fn visit_u64<E: de::Error>(self, v: u64) -> Result<Number, E> {
                Ok(Number::Value(v as f64))
            }
            fn visit_str<E: de::Error>(self, v: &str) -> Result<Number, E> {
                Ok(Number::Expr(v.to_string()))
            }
        }
        d.deserialize_any(V)
    }
}

/// `atol`: one number, or one per component of `(q, q̇)`.
#[derive(Clone)]
pub(crate) enum RawAtol {
    Scalar(f64),
    List(Vec<f64>),
}

impl<'de> Deserialize<'de> for RawAtol {
    fn deserialize<D: Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        struct V;
        impl<'de> Visitor<'de> for V {
            type Value = RawAtol;
            fn expecting(&self, f: &mut fmt::Formatter) -> fmt::Result {
                f.write_str(
                    "a number, or a list of 2N numbers (the coordinates' absolute tolerances, then the velocities')",
                )
            }
            fn visit_f64<E: de::Error>(self, v: f64) -> Result<RawAtol, E> {
                Ok(RawAtol::Scalar(v))
            }
            fn visit_i64<E: de::Error>(self, v: i64) -> Result<RawAtol, E> {
                Ok(RawAtol::Scalar(v as f64))
            }
            fn visit_seq<A: SeqAccess<'de>>(self, mut seq: A) -> Result<RawAtol, A::Error> {
                let mut v = Vec::new();
                while let Some(x) = seq.next_element::<f64>()? {
                    v.push(x);
                }
                Ok(RawAtol::List(v))
            }
        }
        d.deserialize_any(V)
    }
}

/// `output.times`.
#[derive(Clone)]
pub(crate) enum RawTimes {
    Steps,
    /// Numbers, or constant expressions of the parameters.
    List(Vec<Number>),
    Grid {
        from: Option<Number>,
        to: Option<Number>,
        count: i64,
    },
}

impl<'de> Deserialize<'de> for RawTimes {
    fn deserialize<D: Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        struct V;
        impl<'de> Visitor<'de> for V {
            type Value = RawTimes;
            fn expecting(&self, f: &mut fmt::Formatter) -> fmt::Result {
                f.write_str(
                    "\"steps\", a list of times, or a grid { from = 0.0, to = \"end\", count = 101 }",
                )
            }
            fn visit_str<E: de::Error>(self, v: &str) -> Result<RawTimes, E> {
                match v {
                    "steps" => Ok(RawTimes::Steps),
                    other => Err(E::custom(format!(
                        "unknown output times \"{other}\": expected \"steps\", a list of times, or a grid \
                         {{ from = 0.0, to = \"end\", count = 101 }}"
                    ))),
                }
            }
            fn visit_seq<A: SeqAccess<'de>>(self, mut seq: A) -> Result<RawTimes, A::Error> {
                let mut v = Vec::new();
                while let Some(x) = seq.next_element::<Number>()? {
                    v.push(x);
                }
                Ok(RawTimes::List(v))
            }
            fn visit_map<A: MapAccess<'de>>(self, mut map: A) -> Result<RawTimes, A::Error> {
                let (mut from, mut to, mut count) = (None, None, None);
                while let Some(key) = map.next_key::<String>()? {
                    match key.as_str() {
                        "from" => from = Some(map.next_value::<Number>()?),
                        "to" => to = Some(map.next_value::<Number>()?),
                        "count" => count = Some(map.next_value::<i64>()?),
                        other => {
                            return Err(de::Error::custom(format!(
                                "unknown key `{other}` in the output grid: expected `from`, `to`, `count`"
                            )))
                        }
                    }
                }
                let count = count.ok_or_else(|| {
                    de::Error::custom(
                        "the output grid needs `count`, the number of times (at least 2), as in \
                         { from = 0.0, to = \"end\", count = 101 }",
                    )
                })?;
                Ok(RawTimes::Grid { from, to, count })
            }
        }
        d.deserialize_any(V)
    }
}
