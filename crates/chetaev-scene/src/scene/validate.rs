//! From the file as written ([`schema`](super::schema)) to the validated [`Scene`]: names,
//! expressions, sizes, numbers and options, each mistake located in the file.

use std::collections::{BTreeMap, HashSet};
use std::ops::Range;
use std::path::{Path, PathBuf};

use chetaev::prelude::{Atol, Direction};
use toml::Spanned;

use super::schema::{
    Number, RawAtol, RawDirection, RawLoad, RawOutput, RawScene, RawSolve, RawTimes, RawTrajectory,
};
use super::sensitivities::reads;
use super::spec::{
    EventSpec, GridEnd, LoadSpans, LoadSpec, OutputSpec, Picture, Scene, SolveSpec, Spans, Table,
    Times, Units,
};
use super::MAX_OUTPUT_TIMES;
use crate::error::{Error, SourceFile, Warning};
use crate::expr::{is_function, Expr, Symbols, RESERVED};
use crate::output::summary_number;
use crate::source::string_offset;

/// toml's messages, with a hint for the commonest mistakes.
pub(super) fn toml_message(message: &str) -> String {
    let m = message.trim_end().to_string();
    if m.contains("missing field") {
        format!("{m}; see docs/scenes.md for the keys of each table")
    } else {
        m
    }
}

pub(super) struct Builder {
    pub(super) file: SourceFile,
    /// The warnings found so far, each place possibly more than once (an expression is resolved
    /// with and without its varying parameters).
    pub(super) warnings: std::cell::RefCell<Vec<Warning>>,
}

/// "1 value", "3 values".
fn values(n: usize) -> String {
    if n == 1 {
        "1 value".to_string()
    } else {
        format!("{n} values")
    }
}

fn is_identifier(s: &str) -> bool {
    let mut c = s.chars();
    c.next()
        .is_some_and(|f| f.is_ascii_alphabetic() || f == '_')
        && c.all(|x| x.is_ascii_alphanumeric() || x == '_')
}

impl Builder {
    /// `[initial] independent_coordinates` and `independent_speeds` as indices: names of
    /// coordinates (a speed as `x` or `x_dot`), each once; refused together with
    /// `project_velocity`.
    fn independent(
        &self,
        initial: &super::schema::RawInitial,
        coordinates: &[String],
    ) -> Result<Option<chetaev::manifold::Independent>, Error> {
        let (c, v) = (
            &initial.independent_coordinates,
            &initial.independent_speeds,
        );
        if c.is_none() && v.is_none() {
            return Ok(None);
        }
        if initial.project_velocity {
            let span = v.as_ref().or(c.as_ref()).map_or(0..0, Spanned::span);
            return Err(self.err(
                span,
                "independent_coordinates and independent_speeds solve the dependent values from \
                 the constraints, and project_velocity = true projects the whole state onto them: \
                 choose one (remove project_velocity to keep the independent values as given)",
            ));
        }
        let resolve = |list: &Option<Spanned<Vec<Spanned<String>>>>,
                       speeds: bool|
         -> Result<Option<Vec<usize>>, Error> {
            let Some(list) = list else { return Ok(None) };
            let mut out = Vec::new();
            for name in list.get_ref() {
                let text = name.get_ref();
                let base = if speeds {
                    text.strip_suffix("_dot").unwrap_or(text)
                } else {
                    text
                };
                let Some(i) = coordinates.iter().position(|c| c == base) else {
                    let hint = match crate::expr::closest(base, coordinates) {
                        Some(s) => format!("did you mean '{s}'?"),
                        None => format!("the coordinates are {}", coordinates.join(", ")),
                    };
                    return Err(
                        self.err(name.span(), format!("'{text}' is not a coordinate; {hint}"))
                    );
                };
                if out.contains(&i) {
                    return Err(self.err(name.span(), format!("'{text}' is listed twice")));
                }
                out.push(i);
            }
            Ok(Some(out))
        };
        Ok(Some(chetaev::manifold::Independent {
            coordinates: resolve(c, false)?,
            speeds: resolve(v, true)?,
        }))
    }

    pub(super) fn err(&self, range: Range<usize>, message: impl Into<String>) -> Error {
        self.file.error(range, message)
    }

    /// Parses an expression given as a TOML string; errors point into the string.
    pub(super) fn expr(&self, s: &Spanned<String>, symbols: &Symbols) -> Result<Expr, Error> {
        let e = Expr::parse(s.get_ref(), symbols).map_err(|e| self.expr_error(s, e))?;
        self.warn_euler(s, &e);
        Ok(e)
    }

    /// A warning at each `e` of `e` (written as `s`) that is Euler's number: a physicist's `e` is
    /// more often a charge whose parameter was forgotten.
    pub(super) fn warn_euler(&self, s: &Spanned<String>, e: &Expr) {
        let span = s.span();
        for r in e.euler() {
            let start = string_offset(&self.file.text, &span, s.get_ref(), r.start);
            let end = string_offset(&self.file.text, &span, s.get_ref(), r.end).max(start + 1);
            self.warnings.borrow_mut().push(self.file.warning(
                start..end,
                "'e' is Euler's number 2.718281828… here, since no parameter or coordinate is named e: write \
                 exp(1) if that is meant, or declare e under [parameters] (a charge, say) to use \
                 that value",
            ));
        }
    }

    pub(super) fn expr_error(&self, s: &Spanned<String>, e: crate::expr::ExprError) -> Error {
        let span = s.span();
        let start = string_offset(&self.file.text, &span, s.get_ref(), e.start);
        let end = string_offset(&self.file.text, &span, s.get_ref(), e.end).max(start + 1);
        self.err(start..end, e.message)
    }

    /// A constant: a number, or an expression of the parameters.
    pub(super) fn number(
        &self,
        n: &Spanned<Number>,
        symbols: &Symbols,
        what: &str,
    ) -> Result<f64, Error> {
        let v = match n.get_ref() {
            Number::Value(v) => *v,
            Number::Expr(s) => {
                let s = Spanned::new(n.span(), s.clone());
                let e = self.expr(&s, symbols)?;
                e.constant().ok_or_else(|| {
                    self.err(
                        n.span(),
                        format!("{what} must be a constant: use only numbers and parameters"),
                    )
                })?
            }
        };
        if !v.is_finite() {
            return Err(self.err(n.span(), format!("{what} is {v}; give a finite number")));
        }
        Ok(v)
    }

    pub(super) fn name_check(&self, name: &Spanned<String>, what: &str) -> Result<(), Error> {
        let n = name.get_ref();
        if !is_identifier(n) {
            return Err(self.err(
                name.span(),
                format!(
                    "'{n}' is not a valid {what} name: use ASCII letters, digits and '_', starting with a letter or '_'"
                ),
            ));
        }
        if RESERVED.contains(&n.as_str()) {
            return Err(self.err(
                name.span(),
                format!("'{n}' is reserved for time; choose another {what} name"),
            ));
        }
        if is_function(n) {
            return Err(self.err(
                name.span(),
                format!(
                    "'{n}' is a function of the expression language; choose another {what} name"
                ),
            ));
        }
        if n.ends_with("_dot") {
            return Err(self.err(
                name.span(),
                format!("'{n}' ends in _dot, which names velocities; choose another {what} name"),
            ));
        }
        Ok(())
    }

    pub(super) fn build(&self, raw: RawScene) -> Result<Scene, Error> {
        let sensitivity = raw.sensitivities.as_ref().map(Spanned::get_ref);
        let resolved = self.parameters(
            &raw.parameters,
            sensitivity.map(|s| &s.parameters),
            raw.model.get_ref().coordinates.get_ref(),
        )?;
        let parameters = resolved.values.clone();
        let param_map: BTreeMap<String, f64> = parameters.iter().cloned().collect();
        // The coordinates are named only so that one used in a constant (`t_end = "x"`) is
        // called a coordinate, not an unknown name.
        let constants = Symbols {
            coordinates: raw
                .model
                .get_ref()
                .coordinates
                .get_ref()
                .iter()
                .map(|c| c.get_ref().clone())
                .collect(),
            ..Symbols::constants(&param_map)
        };
        // Where sensitivities are asked for, the parameters that move with them are kept as
        // parameter nodes; every expression is also resolved without them first, so that it is
        // checked (folded parts finite, divisions by a zero parameter) exactly as without.
        let varying = resolved.varying();
        let varying_constants = Symbols {
            varying: varying.clone(),
            ..constants.clone()
        };

        // [model]
        let model = raw.model.get_ref();
        let coords = model.coordinates.get_ref();
        let n = coords.len();
        if n == 0 {
            return Err(self.err(
                model.coordinates.span(),
                "no coordinates: list at least one, as in coordinates = [\"x\", \"y\"]",
            ));
        }
        let mut seen = HashSet::new();
        for c in coords {
            self.name_check(c, "coordinate")?;
            if param_map.contains_key(c.get_ref()) {
                return Err(self.err(
                    c.span(),
                    format!(
                        "'{}' is both a parameter and a coordinate; rename one",
                        c.get_ref()
                    ),
                ));
            }
            if !seen.insert(c.get_ref().clone()) {
                return Err(self.err(
                    c.span(),
                    format!("the coordinate '{}' is listed twice", c.get_ref()),
                ));
            }
        }
        let coordinates: Vec<String> = coords.iter().map(|c| c.get_ref().clone()).collect();
        let motion = Symbols {
            parameters: param_map.clone(),
            coordinates: coordinates.clone(),
            varying: BTreeMap::new(),
            motion: true,
            recorded: Vec::new(),
        };
        let varying_motion = (!varying.is_empty()).then(|| Symbols {
            varying: varying.clone(),
            ..motion.clone()
        });
        // An expression of the model or of an event: with parameter nodes where sensitivities
        // are asked for.
        let model_expr = |s: &Spanned<String>| -> Result<Expr, Error> {
            let folded = self.expr(s, &motion)?;
            match &varying_motion {
                Some(symbols) => self.expr(s, symbols),
                None => Ok(folded),
            }
        };
        let lagrangian = model_expr(&model.lagrangian)?;
        let mut constraints = Vec::new();
        let mut constraint_spans = Vec::new();
        if let Some(list) = &model.constraints {
            let k = list.get_ref().len();
            if k > n {
                return Err(self.err(
                    list.span(),
                    format!(
                        "{k} constraints on {n} coordinates: at most {n} independent velocity constraints \
                         can hold at once (K ≤ N; see 'Sizes' in docs/scenes.md)"
                    ),
                ));
            }
            for c in list.get_ref() {
                let f = model_expr(c)?;
                if !f.uses_velocities() {
                    let example = match coordinates.as_slice() {
                        [x, y, ..] => format!("{x}^2 + {y}^2 - l^2"),
                        [x] => format!("{x} - a"),
                        [] => "x^2 + y^2 - l^2".to_string(),
                    };
                    return Err(self.err(
                        c.span(),
                        format!(
                            "this constraint has no velocity in it: it is a position constraint \
                             h(t, q) = 0, and `constraints` takes constraints on the velocities \
                             f(t, q, q_dot) = 0; a position constraint goes under \
                             `holonomic = [...]` in [model], as in holonomic = [\"{example}\"]"
                        ),
                    ));
                }
                constraints.push(f);
                constraint_spans.push(c.span());
            }
        }
        let mut holonomic = Vec::new();
        let mut holonomic_spans = Vec::new();
        if let Some(list) = &model.holonomic {
            let total = constraints.len() + list.get_ref().len();
            if total > n {
                return Err(self.err(
                    list.span(),
                    format!(
                        "{total} constraints in all (velocity and holonomic) on {n} coordinates: at most \
                         {n} can hold at once"
                    ),
                ));
            }
            for h in list.get_ref() {
                let text = h.get_ref();
                let velocity = coordinates.iter().find(|c| {
                    let name = format!("{c}_dot");
                    text.match_indices(&name).any(|(at, _)| {
                        let before = text[..at].chars().next_back();
                        let after = text[at + name.len()..].chars().next();
                        let ident =
                            |c: Option<char>| c.is_some_and(|c| c.is_alphanumeric() || c == '_');
                        !ident(before) && !ident(after)
                    })
                });
                if let Some(c) = velocity {
                    return Err(self.err(
                        h.span(),
                        format!(
                            "a holonomic constraint h(t, q) = 0 depends on positions and time only, but \
                             this one uses {c}_dot; put constraints on velocities under `constraints`"
                        ),
                    ));
                }
                holonomic.push(model_expr(h)?);
                holonomic_spans.push(h.span());
            }
        }
        let mut forces = Vec::new();
        let mut force_spans = Vec::new();
        if let Some(list) = &model.forces {
            if list.get_ref().len() != n {
                return Err(self.err(
                    list.span(),
                    format!(
                        "{} for {n} coordinates: give one generalised force Q_i per coordinate, in \
                         the order of `coordinates` (0 where a coordinate has none)",
                        match list.get_ref().len() {
                            1 => "1 force".to_string(),
                            k => format!("{k} forces"),
                        }
                    ),
                ));
            }
            for f in list.get_ref() {
                forces.push(model_expr(f)?);
                force_spans.push(f.span());
            }
        }
        let dissipation = match &model.dissipation {
            Some(d) => Some(model_expr(d)?),
            None => None,
        };
        let (loads, load_spans) = self.loads(&raw.loads, &model_expr)?;
        let mut units = self.model_units(
            model.units.as_ref(),
            &coordinates,
            constraints.len() + holonomic.len(),
        )?;

        // [initial]
        let initial = raw.initial.get_ref();
        let t0 = match &initial.t {
            Some(t) => self.number(t, &constants, "initial.t")?,
            None => 0.0,
        };
        let q0 = self.vector(&initial.q, &coordinates, "q", &constants)?;
        let qd0 = self.vector(&initial.q_dot, &coordinates, "q_dot", &constants)?;
        let independent = self.independent(initial, &coordinates)?;
        let (q_rates, qd_rates) = match &raw.sensitivities {
            None => (Vec::new(), Vec::new()),
            Some(s) => {
                if let Some(Number::Expr(text)) = initial.t.as_ref().map(Spanned::get_ref) {
                    let t = self.expr(
                        &Spanned::new(initial.t.as_ref().map_or(0..0, Spanned::span), text.clone()),
                        &varying_constants,
                    )?;
                    if !t.varying_parameters().is_empty() {
                        return Err(self.err(
                            initial.t.as_ref().map_or(0..0, Spanned::span),
                            "the initial time depends on a parameter named under [sensitivities], \
                             but sensitivities are taken at a fixed initial time; give initial.t \
                             without that parameter",
                        ));
                    }
                }
                if independent.is_some() {
                    return Err(self.err(
                        s.get_ref().parameters.span(),
                        "[sensitivities] cannot be combined with independent_coordinates or \
                         independent_speeds under [initial]: the derivatives of the completed state \
                         are not computed; give a q and q_dot that satisfy the constraints, written \
                         with the parameters they depend on, and remove the independent lists",
                    ));
                }
                if initial.project_velocity {
                    return Err(self.err(
                        s.get_ref().parameters.span(),
                        "[sensitivities] cannot be combined with project_velocity = true under \
                         [initial]: the derivatives of the projected velocity are not computed; give \
                         a q_dot that satisfies the constraints, written with the parameters it \
                         depends on (as in q_dot = [\"v0\", 0.0]), and remove project_velocity",
                    ));
                }
                (
                    self.initial_rates(&initial.q, &varying_constants, &resolved)?,
                    self.initial_rates(&initial.q_dot, &varying_constants, &resolved)?,
                )
            }
        };

        // [solve]
        let (solve, options) = self.solve(raw.solve.get_ref(), n, &constants)?;
        if let (Some(s), true) = (&raw.sensitivities, solve.projection) {
            return Err(self.err(
                s.get_ref().parameters.span(),
                "[sensitivities] cannot be combined with projection = true under [solve]: the \
                 projection would move the state but not its derivatives; remove projection (the \
                 sensitivities stay on the linearised constraints without it)",
            ));
        }
        let control = raw
            .sensitivities
            .as_ref()
            .and_then(|s| s.get_ref().control.as_ref());
        if let Some(c) = control.filter(|c| *c.get_ref()) {
            use chetaev::integrate::Method;
            let info = solve.method.info();
            if info.fixed_step.is_some() {
                return Err(self.err(
                    c.span(),
                    format!(
                        "control = true puts the sensitivities under the error control of an \
                         adaptive method; {} takes every step of size `step` and has no error \
                         control, so it would be ignored: remove it",
                        info.name.to_lowercase()
                    ),
                ));
            }
        }
        if solve.t_end == t0 {
            return Err(self.err(
                raw.solve.get_ref().t_end.span(),
                format!(
                    "t_end = {} equals the initial time: nothing to integrate; give a later t_end, or \
                     an earlier one to integrate backwards (`chetaev describe` shows the equations \
                     at the initial state without integrating)",
                    solve.t_end
                ),
            ));
        }

        // [[events]]
        let mut events = Vec::new();
        let mut event_spans = Vec::new();
        let mut names = HashSet::new();
        for e in &raw.events {
            let e = e.get_ref();
            if !names.insert(e.name.get_ref().clone()) {
                return Err(self.err(
                    e.name.span(),
                    format!(
                        "two events are named '{}'; names must differ",
                        e.name.get_ref()
                    ),
                ));
            }
            if e.name.get_ref().trim().is_empty() {
                return Err(self.err(e.name.span(), "an event needs a non-empty name"));
            }
            events.push(EventSpec {
                name: e.name.get_ref().clone(),
                expr: model_expr(&e.expression)?,
                direction: match e.direction {
                    None | Some(RawDirection::Either) => Direction::Either,
                    Some(RawDirection::Rising) => Direction::Rising,
                    Some(RawDirection::Falling) => Direction::Falling,
                },
                terminal: e.terminal,
            });
            event_spans.push(e.expression.span());
        }

        // [output]
        let stem = Path::new(&self.file.path)
            .file_stem()
            .map_or_else(|| "scene".to_string(), |s| s.to_string_lossy().into_owned());
        let (output, quantity_spans) = self.output(
            raw.output.as_ref(),
            &stem,
            constraints.len() + holonomic.len(),
            &motion,
            &constants,
            t0,
            solve.t_end,
        )?;
        units.quantities = self.quantity_units(raw.output.as_ref(), &output.quantities)?;
        let sensitivities = match &raw.sensitivities {
            Some(s) => {
                self.check_holonomic(&holonomic, t0, &q0, &q_rates, &resolved, initial.q.span())?;
                let exprs = std::iter::once(&lagrangian)
                    .chain(&constraints)
                    .chain(&holonomic)
                    .chain(&forces)
                    .chain(&dissipation)
                    .chain(loads.iter().flat_map(|l| {
                        let (place, acting) = l.parts();
                        place.iter().chain(acting)
                    }))
                    .chain(events.iter().map(|e| &e.expr));
                Some(self.seeds(s.get_ref(), &resolved, &reads(exprs), &q_rates, &qd_rates)?)
            }
            None => {
                let asked = raw.output.as_ref().and_then(|o| {
                    o.tables
                        .iter()
                        .find(|t| *t.get_ref() == Table::Sensitivities)
                });
                if let Some(t) = asked {
                    return Err(self.err(
                        t.span(),
                        "the 'sensitivities' table needs the parameters to differentiate with \
                         respect to: add a [sensitivities] table, as in [sensitivities] \
                         parameters = [\"g\"], or remove 'sensitivities' from the list",
                    ));
                }
                None
            }
        };

        let meta = raw.scene.as_ref();
        Ok(Scene {
            name: meta
                .and_then(|m| m.name.clone())
                .unwrap_or_else(|| stem.clone()),
            description: meta.and_then(|m| m.description.clone()),
            file: self.file.clone(),
            parameters,
            coordinates,
            lagrangian,
            constraints,
            holonomic,
            forces,
            dissipation,
            loads,
            t0,
            q0,
            qd0,
            project_velocity: initial.project_velocity,
            independent,
            solve,
            events,
            sensitivities,
            output,
            units,
            warnings: {
                let mut w = self.warnings.take();
                w.sort_by_key(|w| (w.line, w.column));
                w.dedup();
                w
            },
            spans: Spans {
                initial: raw.initial.span(),
                independent: initial
                    .independent_speeds
                    .as_ref()
                    .or(initial.independent_coordinates.as_ref())
                    .map_or_else(|| raw.initial.span(), Spanned::span),
                q: initial.q.span(),
                q_dot: initial.q_dot.span(),
                constraints: constraint_spans,
                holonomic: holonomic_spans,
                forces: force_spans,
                dissipation: model.dissipation.as_ref().map(Spanned::span),
                loads: load_spans,
                lagrangian: model.lagrangian.span(),
                solve: raw.solve.span(),
                options,
                events: event_spans,
                quantities: quantity_spans,
                sensitivities: raw
                    .sensitivities
                    .as_ref()
                    .map_or(0..0, |s| s.get_ref().parameters.span()),
            },
        })
    }

    /// `[[loads]]`: each a force on a point or a torque on a body, its lists of matching lengths,
    /// a point without velocities and an angular velocity with one; with the places of the
    /// components of each.
    fn loads(
        &self,
        raw: &[Spanned<RawLoad>],
        model_expr: &dyn Fn(&Spanned<String>) -> Result<Expr, Error>,
    ) -> Result<(Vec<LoadSpec>, Vec<LoadSpans>), Error> {
        const POINT: &str =
            "point = [\"l*sin(theta)\", \"-l*cos(theta)\"] with force = [\"F\", \"0\"]";
        const BODY: &str = "angular_velocity = [\"theta_dot\"] with torque = [\"-c*theta_dot\"]";
        let mut loads = Vec::new();
        let mut spans = Vec::new();
        for table in raw {
            let load = table.get_ref();
            let (place, acting, torque) = match (
                &load.point,
                &load.force,
                &load.angular_velocity,
                &load.torque,
            ) {
                (Some(_), _, Some(w), _) => return Err(self.err(
                    w.span(),
                    "a [[loads]] table holds one load: a force on a point (point and force) or \
                         a torque on a body (angular_velocity and torque), not both; put each in \
                         its own [[loads]] table",
                )),
                (Some(p), Some(f), None, None) => (p, f, false),
                (None, None, Some(w), Some(t)) => (w, t, true),
                (Some(_), _, None, Some(t)) => {
                    return Err(self.err(
                        t.span(),
                        format!(
                            "a torque acts on a body, not on a point: give it in its own [[loads]] \
                             table with the body's angular velocity, as in {BODY}; the point takes \
                             force = [...]"
                        ),
                    ))
                }
                (None, Some(f), Some(_), _) => {
                    return Err(self.err(
                        f.span(),
                        format!(
                            "a force acts on a point, not on a body: give it in its own [[loads]] \
                             table with the point's position, as in {POINT}; the angular velocity \
                             takes torque = [...]"
                        ),
                    ))
                }
                (Some(p), None, None, None) => {
                    return Err(self.err(
                        p.span(),
                        format!(
                            "this point has no force on it: add force = [...], F(t, q, q_dot) with \
                             one component per component of the point, as in {POINT}"
                        ),
                    ))
                }
                (None, None, Some(w), None) => {
                    return Err(self.err(
                        w.span(),
                        format!(
                            "this angular velocity has no torque on it: add torque = [...], \
                             T(t, q, q_dot) with one component per component of the angular \
                             velocity, as in {BODY}"
                        ),
                    ))
                }
                (None, Some(f), None, _) => {
                    return Err(self.err(
                        f.span(),
                        format!(
                            "a force needs the point it acts on: add point = [...], its position \
                             r(t, q) with one component per component of the force, as in {POINT}"
                        ),
                    ))
                }
                (None, None, None, Some(t)) => {
                    return Err(self.err(
                        t.span(),
                        format!(
                            "a torque needs the body it acts on: add angular_velocity = [...], \
                             the body's ω(t, q, q_dot) with one component per component of the \
                             torque, as in {BODY}"
                        ),
                    ))
                }
                (None, None, None, None) => {
                    return Err(self.err(
                        table.span(),
                        format!(
                            "this load says neither where nor what acts: give a force on a point, \
                             as in {POINT}, or a torque on a body, as in {BODY}"
                        ),
                    ))
                }
            };
            let d = place.get_ref().len();
            let (where_, what, sizes) = if torque {
                ("angular velocity", "torque", [1, 3])
            } else {
                ("point", "force", [2, 3])
            };
            let components = |k: usize| match k {
                1 => "1 component".to_string(),
                k => format!("{k} components"),
            };
            if !sizes.contains(&d) {
                return Err(self.err(
                    place.span(),
                    format!(
                        "the {where_} has {}: give {} in the plane or {} in space{}",
                        components(d),
                        components(sizes[0]),
                        sizes[1],
                        if torque {
                            " (in the plane, the rate about the plane's normal)"
                        } else {
                            ""
                        }
                    ),
                ));
            }
            if acting.get_ref().len() != d {
                return Err(self.err(
                    acting.span(),
                    format!(
                        "the {what} has {} and the {where_} {}: give one per component of the \
                         {where_}, in the same axes",
                        components(acting.get_ref().len()),
                        components(d)
                    ),
                ));
            }
            let mut exprs = Vec::new();
            for c in place.get_ref() {
                let e = model_expr(c)?;
                if !torque && e.uses_velocities() {
                    return Err(self.err(
                        c.span(),
                        "the point's position r(t, q) depends on the coordinates and time only, \
                         but this component uses a velocity (a name ending in _dot); a force that \
                         depends on the velocities goes under force = [...]",
                    ));
                }
                exprs.push(e);
            }
            if torque && !exprs.iter().any(Expr::uses_velocities) {
                return Err(self.err(
                    place.span(),
                    format!(
                        "no component of this angular velocity uses a velocity, so the torque \
                         does no virtual work and has no generalised force: ω(t, q, q_dot) is the \
                         body's rate of turning, as in {BODY}"
                    ),
                ));
            }
            let values = acting
                .get_ref()
                .iter()
                .map(model_expr)
                .collect::<Result<Vec<_>, _>>()?;
            spans.push((
                place.get_ref().iter().map(Spanned::span).collect(),
                acting.get_ref().iter().map(Spanned::span).collect(),
            ));
            loads.push(if torque {
                LoadSpec::Torque {
                    angular_velocity: exprs,
                    torque: values,
                }
            } else {
                LoadSpec::Force {
                    point: exprs,
                    force: values,
                }
            });
        }
        Ok((loads, spans))
    }

    fn vector(
        &self,
        list: &Spanned<Vec<Spanned<Number>>>,
        coordinates: &[String],
        what: &str,
        constants: &Symbols,
    ) -> Result<Vec<f64>, Error> {
        let n = coordinates.len();
        if list.get_ref().len() != n {
            let names: Vec<String> = coordinates
                .iter()
                .map(|c| {
                    if what == "q" {
                        c.clone()
                    } else {
                        format!("{c}_dot")
                    }
                })
                .collect();
            return Err(self.err(
                list.span(),
                format!(
                    "initial.{what} has {}; expected {n}, one for each of {}",
                    values(list.get_ref().len()),
                    names.join(", ")
                ),
            ));
        }
        list.get_ref()
            .iter()
            .enumerate()
            .map(|(i, v)| {
                let name = if what == "q" {
                    coordinates[i].clone()
                } else {
                    format!("{}_dot", coordinates[i])
                };
                self.number(v, constants, &format!("the initial value of {name}"))
            })
            .collect()
    }

    #[allow(clippy::type_complexity)]
    fn solve(
        &self,
        raw: &RawSolve,
        n: usize,
        constants: &Symbols,
    ) -> Result<(SolveSpec, BTreeMap<&'static str, Range<usize>>), Error> {
        let mut spans = BTreeMap::new();
        use chetaev::integrate::{AnyMethod, Method};
        let (name, method_span) = raw
            .method
            .as_ref()
            .map_or(("dop853", 0..0), |m| (m.get_ref().as_str(), m.span()));
        // The library's names; the step of a fixed-step method is set below, once it is known to
        // be wanted.
        let mut method = AnyMethod::from_name(name, Some(1.0))
            .map_err(|e| self.err(method_span.clone(), e.to_string()))?;
        let info = method.info();
        let fixed = info.fixed_step.is_some();
        if let Some(s) = &raw.stiffness_detection {
            if method.stiffness_detection_mut().is_none() {
                return Err(self.err(
                    s.span(),
                    format!(
                        "stiffness_detection applies to {} only; remove it",
                        stiffness_methods()
                    ),
                ));
            }
        }
        let key = info.name.to_lowercase();
        let step = match (&raw.step, fixed) {
            (Some(s), true) => {
                spans.insert("step", s.span());
                let h = self.number(s, constants, "solve.step")?;
                if h <= 0.0 {
                    return Err(self.err(
                        s.span(),
                        format!("solve.step = {h}: the step of {key} must be positive"),
                    ));
                }
                h
            }
            (None, true) => {
                return Err(self.err(
                    method_span,
                    format!(
                        "{key} takes a fixed step: add `step = ...` under [solve] (or choose an \
                         adaptive method: {})",
                        adaptive_methods()
                    ),
                ));
            }
            (Some(s), false) => {
                return Err(self.err(
                    s.span(),
                    format!(
                        "`step` is the fixed step of {}; {key} is adaptive and chooses its own \
                         steps (use initial_step or max_step to guide it)",
                        fixed_methods()
                    ),
                ));
            }
            (None, false) => 0.0,
        };
        if fixed {
            // A fixed-step method takes every step of size `step` (the first one too) and has no
            // error control: these keys would be ignored. (`max_step` is not: it caps the step.)
            let tolerance = |name: &str| {
                format!(
                    "`{name}` is the tolerance of the adaptive methods' error control; {key} takes \
                     every step of size `step` and has no error control, so it would be ignored: \
                     remove it and set the accuracy with `step` (halve it to see how much the \
                     result moves), or choose an adaptive method ({}) to keep the tolerance",
                    adaptive_methods()
                )
            };
            if let Some(r) = &raw.rtol {
                return Err(self.err(r.span(), tolerance("rtol")));
            }
            if let Some(a) = &raw.atol {
                return Err(self.err(a.span(), tolerance("atol")));
            }
            if let Some(h) = &raw.initial_step {
                return Err(self.err(
                    h.span(),
                    format!(
                        "`initial_step` is the first step of an adaptive method; {key} takes every \
                         step of size `step`, the first one too, so it would be ignored: remove it \
                         and set `step`"
                    ),
                ));
            }
        }
        if fixed {
            method = AnyMethod::from_name(name, Some(step))
                .map_err(|e| self.err(method_span.clone(), e.to_string()))?;
        }
        if let (Some(s), Some(detection)) =
            (&raw.stiffness_detection, method.stiffness_detection_mut())
        {
            detection.enabled = *s.get_ref();
        }
        let t_end = self.number(&raw.t_end, constants, "solve.t_end")?;
        spans.insert("t_end", raw.t_end.span());
        let defaults = chetaev::prelude::Options::until(0.0);
        let rtol = match &raw.rtol {
            Some(r) => {
                spans.insert("rtol", r.span());
                *r.get_ref()
            }
            None => defaults.rtol,
        };
        let atol = match &raw.atol {
            Some(a) => {
                spans.insert("atol", a.span());
                spans.insert("atol (length)", a.span());
                match a.get_ref() {
                    RawAtol::Scalar(x) => Atol::Scalar(*x),
                    RawAtol::List(v) => {
                        if v.len() != 2 * n {
                            return Err(self.err(
                                a.span(),
                                format!(
                                    "atol has {}; a list needs {} (one per coordinate, then one per velocity), or give one number",
                                    values(v.len()),
                                    2 * n
                                ),
                            ));
                        }
                        Atol::PerComponent(v.clone())
                    }
                }
            }
            None => defaults.atol.clone(),
        };
        let optional = |s: &Option<Spanned<Number>>,
                        name: &'static str,
                        spans: &mut BTreeMap<&'static str, Range<usize>>|
         -> Result<Option<f64>, Error> {
            s.as_ref()
                .map(|s| {
                    spans.insert(name, s.span());
                    self.number(s, constants, &format!("solve.{name}"))
                })
                .transpose()
        };
        let initial_step = optional(&raw.initial_step, "initial_step", &mut spans)?;
        let max_step = optional(&raw.max_step, "max_step", &mut spans)?;
        let max_steps = match &raw.max_steps {
            Some(m) => {
                spans.insert("max_steps", m.span());
                let v = *m.get_ref();
                if v < 1 {
                    return Err(self.err(
                        m.span(),
                        format!("max_steps = {v}: allow at least one step"),
                    ));
                }
                Some(usize::try_from(v).unwrap_or(usize::MAX))
            }
            None => None,
        };
        Ok((
            SolveSpec {
                method,
                t_end,
                rtol,
                atol,
                initial_step,
                max_step,
                max_steps,
                projection: raw.projection,
            },
            spans,
        ))
    }

    #[allow(clippy::too_many_arguments)]
    fn output(
        &self,
        raw: Option<&RawOutput>,
        stem: &str,
        k: usize,
        motion: &Symbols,
        constants: &Symbols,
        t0: f64,
        t_end: f64,
    ) -> Result<(OutputSpec, Vec<Range<usize>>), Error> {
        let default_dir = PathBuf::from("out").join(stem);
        let Some(raw) = raw else {
            return Ok((
                OutputSpec {
                    directory: default_dir,
                    times: Times::Steps,
                    tables: Vec::new(),
                    pictures: Vec::new(),
                    quantities: Vec::new(),
                    trajectory: None,
                },
                Vec::new(),
            ));
        };
        let no_constraints = |what: &str, span: Range<usize>| {
            self.err(
                span,
                format!(
                    "the model has no constraints, so there is no {what}; remove it from the list"
                ),
            )
        };
        let mut tables = Vec::new();
        for t in &raw.tables {
            if t.get_ref().needs_constraints() && k == 0 {
                return Err(no_constraints(
                    &format!("'{}' table", t.get_ref().name()),
                    t.span(),
                ));
            }
            if !tables.contains(t.get_ref()) {
                tables.push(*t.get_ref());
            }
        }
        let mut pictures = Vec::new();
        for p in &raw.pictures {
            if p.get_ref().needs_constraints() && k == 0 {
                return Err(no_constraints(
                    &format!("'{}' picture", p.get_ref().name()),
                    p.span(),
                ));
            }
            if !pictures.contains(p.get_ref()) {
                pictures.push(*p.get_ref());
            }
        }
        let mut entries: Vec<(&Spanned<String>, &Spanned<String>)> =
            raw.quantities.iter().collect();
        entries.sort_by_key(|(k, _)| k.span().start);
        let mut quantities = Vec::new();
        let mut spans = Vec::new();
        let along = quantity_symbols(motion, k);
        for (name, value) in entries {
            if !is_identifier(name.get_ref()) {
                return Err(self.err(
                    name.span(),
                    format!(
                        "'{}' is not a valid quantity name: use ASCII letters, digits and '_', \
                         starting with a letter or '_'",
                        name.get_ref()
                    ),
                ));
            }
            if name.get_ref() == "t" {
                return Err(self.err(
                    name.span(),
                    "'t' names the time column of quantities.csv already; choose another \
                     quantity name, such as 'time'",
                ));
            }
            quantities.push((name.get_ref().clone(), self.expr(value, &along)?));
            spans.push(value.span());
        }
        let wants_quantities =
            tables.contains(&Table::Quantities) || pictures.contains(&Picture::Quantities);
        if wants_quantities && quantities.is_empty() {
            let span = raw
                .tables
                .iter()
                .map(|t| (t.get_ref() == &Table::Quantities, t.span()))
                .chain(
                    raw.pictures
                        .iter()
                        .map(|p| (p.get_ref() == &Picture::Quantities, p.span())),
                )
                .find(|(hit, _)| *hit)
                .map_or(0..0, |(_, s)| s);
            return Err(self.err(
                span,
                "'quantities' asks for the [output.quantities] table, which is empty; add one, as in \
                 speed = \"sqrt(x_dot^2 + y_dot^2)\"",
            ));
        }
        let times = match &raw.times {
            None => Times::Steps,
            Some(t) => self.times(t, constants, t0, t_end)?,
        };
        let trajectory = match &raw.trajectory {
            None => None,
            Some(t) => {
                if !pictures.contains(&Picture::Trajectory) {
                    return Err(self.err(
                        t.span(),
                        "output.trajectory chooses the panels of the 'trajectory' picture, which \
                         `pictures` does not ask for; add \"trajectory\" to `pictures`, or remove this",
                    ));
                }
                Some(self.trajectory(t, &motion.coordinates)?)
            }
        };
        Ok((
            OutputSpec {
                directory: raw.directory.as_ref().map_or(default_dir, PathBuf::from),
                times,
                tables,
                pictures,
                quantities,
                trajectory,
            },
            spans,
        ))
    }

    /// A unit as written: one line of text, spaces around it dropped.
    fn unit(&self, v: &Spanned<String>) -> Result<String, Error> {
        let text = v.get_ref().trim();
        if text.chars().any(char::is_control) {
            return Err(self.err(
                v.span(),
                "a unit is one line of text, such as \"m/s\" or \"kg m/s²\"",
            ));
        }
        if text.chars().count() > 40 {
            return Err(self.err(
                v.span(),
                "a unit of more than 40 characters does not fit an axis label; shorten it",
            ));
        }
        Ok(text.to_string())
    }

    /// `[model] units`: keys `t`, a coordinate, `coordinates` (every coordinate without its own),
    /// `mu` (every multiplier without its own), `mu_1` … `mu_K`, `energy`. A coordinate's own name
    /// wins over the shorthands.
    fn model_units(
        &self,
        raw: Option<&Spanned<BTreeMap<Spanned<String>, Spanned<String>>>>,
        coordinates: &[String],
        k: usize,
    ) -> Result<Units, Error> {
        let mut units = Units {
            coordinates: vec![None; coordinates.len()],
            multipliers: vec![None; k],
            ..Units::default()
        };
        let Some(raw) = raw else {
            return Ok(units);
        };
        let (mut all_coordinates, mut all_multipliers) = (None, None);
        for (key, value) in raw.get_ref() {
            let unit = self.unit(value)?;
            let name = key.get_ref().as_str();
            if let Some(i) = coordinates.iter().position(|c| c == name) {
                units.coordinates[i] = Some(unit);
                continue;
            }
            match name {
                "t" => units.time = Some(unit),
                "coordinates" => all_coordinates = Some(unit),
                "mu" if k > 0 => all_multipliers = Some(unit),
                "energy" => units.energy = Some(unit),
                _ => {
                    let index = name
                        .strip_prefix("mu_")
                        .and_then(|a| a.parse::<usize>().ok())
                        .filter(|a| (1..=k).contains(a));
                    match index {
                        Some(a) => units.multipliers[a - 1] = Some(unit),
                        None if k == 0 && (name == "mu" || name.starts_with("mu_")) => {
                            return Err(self.err(
                                key.span(),
                                format!(
                                    "the model has no constraints, so no multipliers: '{name}' has no unit to \
                                     give; remove it"
                                ),
                            ));
                        }
                        None => {
                            let multipliers = match k {
                                0 => String::new(),
                                1 => ", the multiplier (mu or mu_1)".to_string(),
                                k => format!(", the multipliers (mu for all, or mu_1 … mu_{k})"),
                            };
                            return Err(self.err(
                                key.span(),
                                format!(
                                    "no unit can be given to '{name}': units are given to t, the coordinates \
                                     ({}), all coordinates at once (coordinates){multipliers} and the energy \
                                     (energy); the units of output quantities go in [output.units]",
                                    coordinates.join(", ")
                                ),
                            ));
                        }
                    }
                }
            }
        }
        for u in &mut units.coordinates {
            if u.is_none() {
                u.clone_from(&all_coordinates);
            }
        }
        for u in &mut units.multipliers {
            if u.is_none() {
                u.clone_from(&all_multipliers);
            }
        }
        Ok(units)
    }

    /// `[output.units]`: a unit for each output quantity named.
    fn quantity_units(
        &self,
        raw: Option<&RawOutput>,
        quantities: &[(String, Expr)],
    ) -> Result<Vec<Option<String>>, Error> {
        let mut units = vec![None; quantities.len()];
        let Some(raw) = raw else {
            return Ok(units);
        };
        for (key, value) in &raw.units {
            let name = key.get_ref();
            let Some(i) = quantities.iter().position(|(q, _)| q == name) else {
                let known = if quantities.is_empty() {
                    "[output.quantities] names none".to_string()
                } else {
                    let names: Vec<&str> = quantities.iter().map(|(q, _)| q.as_str()).collect();
                    format!("the quantities are {}", names.join(", "))
                };
                return Err(self.err(
                    key.span(),
                    format!(
                        "'{name}' is not an output quantity: [output.units] gives units to the names of \
                         [output.quantities] ({known}); the units of t and the coordinates go in [model] units"
                    ),
                ));
            };
            units[i] = Some(self.unit(value)?);
        }
        Ok(units)
    }

    /// The place of `name` (in quotes) inside `whole`, or `whole` if it is not found there.
    fn name_in(&self, whole: &Range<usize>, name: &str) -> Range<usize> {
        let text = self.file.text.get(whole.clone()).unwrap_or("");
        ["\"", "'"]
            .iter()
            .find_map(|q| text.find(&format!("{q}{name}{q}")))
            .map_or(whole.clone(), |at| {
                let start = whole.start + at + 1;
                start..start + name.len().max(1)
            })
    }

    /// `output.trajectory`: panels of pairs of coordinates, each name a coordinate.
    fn trajectory(
        &self,
        t: &Spanned<RawTrajectory>,
        coordinates: &[String],
    ) -> Result<Vec<Vec<(usize, usize)>>, Error> {
        let span = t.span();
        let panels = &t.get_ref().0;
        if coordinates.len() < 2 {
            return Err(self.err(
                span,
                "the model has one coordinate, so the trajectory is that coordinate against t; remove \
                 output.trajectory",
            ));
        }
        if panels.is_empty() {
            return Err(self.err(
                span,
                "output.trajectory lists no panel: give pairs of coordinates, as in [[\"x\", \"y\"]], or \
                 remove it for the default",
            ));
        }
        let index = |name: &str| -> Result<usize, Error> {
            coordinates.iter().position(|c| c == name).ok_or_else(|| {
                let hint = if name == "t" {
                    "t is time; the trajectory draws coordinates against each other (the 'state' \
                     picture draws them against t)"
                        .to_string()
                } else {
                    format!("the coordinates are {}", coordinates.join(", "))
                };
                self.err(
                    self.name_in(&span, name),
                    format!("'{name}' is not a coordinate: {hint}"),
                )
            })
        };
        let mut out = Vec::new();
        for panel in panels {
            let mut pairs = Vec::new();
            for pair in panel {
                let [a, b] = pair.as_slice() else {
                    let at = pair
                        .first()
                        .map_or(span.clone(), |n| self.name_in(&span, n));
                    return Err(self.err(
                        at,
                        format!(
                            "a pair of the trajectory names two coordinates, the horizontal then the \
                             vertical axis, as in [\"x\", \"y\"]; this one names {}",
                            match pair.len() {
                                0 => "none".to_string(),
                                1 => "one".to_string(),
                                n => n.to_string(),
                            }
                        ),
                    ));
                };
                let (i, j) = (index(a)?, index(b)?);
                if i == j {
                    return Err(self.err(
                        self.name_in(&span, b),
                        format!("the pair [\"{a}\", \"{b}\"] draws '{a}' against itself; name two coordinates"),
                    ));
                }
                pairs.push((i, j));
            }
            if pairs.is_empty() {
                return Err(self.err(
                    span,
                    "a panel of output.trajectory is empty; give a pair such as [\"x\", \"y\"]",
                ));
            }
            out.push(pairs);
        }
        Ok(out)
    }

    fn times(
        &self,
        t: &Spanned<RawTimes>,
        constants: &Symbols,
        t0: f64,
        t_end: f64,
    ) -> Result<Times, Error> {
        // Output times follow the direction of integration.
        let forward = t_end >= t0;
        let inside = |s: f64| {
            let (lo, hi) = if forward { (t0, t_end) } else { (t_end, t0) };
            s.is_finite() && s >= lo && s <= hi
        };
        let outside = |s: f64| {
            self.err(
                t.span(),
                format!(
                    "output time {} lies outside the integration from t = {} to t_end = {}",
                    summary_number(s),
                    summary_number(t0),
                    summary_number(t_end)
                ),
            )
        };
        Ok(match t.get_ref() {
            RawTimes::Steps => Times::Steps,
            RawTimes::List(v) => {
                let mut times = Vec::with_capacity(v.len());
                for n in v {
                    let s =
                        self.number(&Spanned::new(t.span(), n.clone()), constants, "output time")?;
                    if !inside(s) {
                        return Err(outside(s));
                    }
                    times.push(s);
                }
                // In the direction of integration, each once: rows come out in that order, so a
                // list written otherwise was most likely meant otherwise.
                if let Some(w) =
                    times
                        .windows(2)
                        .find(|w| if forward { w[1] <= w[0] } else { w[1] >= w[0] })
                {
                    return Err(self.err(
                        t.span(),
                        format!(
                            "the output times must be listed in the direction of integration \
                             ({}), each once: {} follows {}; sort the list and drop repeats",
                            if forward {
                                "increasing"
                            } else {
                                "decreasing, as t_end < t"
                            },
                            summary_number(w[1]),
                            summary_number(w[0])
                        ),
                    ));
                }
                Times::List(times)
            }
            RawTimes::Grid { from, to, count } => {
                if *count > MAX_OUTPUT_TIMES {
                    return Err(self.err(
                        t.span(),
                        format!(
                            "the output grid has count = {count}; at most {MAX_OUTPUT_TIMES} times are written"
                        ),
                    ));
                }
                if *count < 2 {
                    return Err(self.err(
                        t.span(),
                        format!(
                            "the output grid has count = {count}; it needs at least 2 times, \
                             `from` and `to` (count = 2 writes the start and the end only)"
                        ),
                    ));
                }
                let constant = |n: &Number, what: &str| -> Result<f64, Error> {
                    self.number(&Spanned::new(t.span(), n.clone()), constants, what)
                };
                let from = match from {
                    Some(n) => constant(n, "output.times.from")?,
                    None => t0,
                };
                let to = match to {
                    None => GridEnd::End,
                    Some(Number::Expr(s)) if s.trim() == "end" => GridEnd::End,
                    Some(Number::Expr(s)) => {
                        let e = Expr::parse(s, constants).map_err(|_| {
                            self.err(
                                t.span(),
                                format!(
                                    "output.times.to = \"{s}\" is not a time: give a number, an expression of the \
                                     parameters, or \"end\" (where the motion stops: at a terminal event, or at t_end)"
                                ),
                            )
                        })?;
                        self.warn_euler(&Spanned::new(t.span(), s.clone()), &e);
                        GridEnd::Time(constant(
                            &Number::Value(e.constant().unwrap_or(f64::NAN)),
                            "output.times.to",
                        )?)
                    }
                    Some(n) => GridEnd::Time(constant(n, "output.times.to")?),
                };
                if !inside(from) {
                    return Err(outside(from));
                }
                if let GridEnd::Time(x) = to {
                    if !inside(x) {
                        return Err(outside(x));
                    }
                    if (forward && x <= from) || (!forward && x >= from) {
                        return Err(self.err(
                            t.span(),
                            format!(
                                "the output grid runs from {} to {}, which is {} the direction of \
                                 integration (t = {} to t_end = {}): give a `to` beyond `from`",
                                summary_number(from),
                                summary_number(x),
                                if x == from {
                                    "no interval in"
                                } else {
                                    "against"
                                },
                                summary_number(t0),
                                summary_number(t_end)
                            ),
                        ));
                    }
                }
                Times::Grid {
                    from,
                    to,
                    count: usize::try_from(*count).unwrap_or(2),
                }
            }
        })
    }
}

/// The scene's names of the methods with error control, "dopri5, dop853, ...", from the library's
/// list.
pub(crate) fn adaptive_methods() -> String {
    use chetaev::integrate::Method;
    method_names(|m| m.info().fixed_step.is_none())
}

/// The scene's names of the methods without error control, from the library's list.
fn fixed_methods() -> String {
    use chetaev::integrate::Method;
    method_names(|m| m.info().fixed_step.is_some())
}

/// The scene's names of the methods that have a stiffness test, from the library's list.
fn stiffness_methods() -> String {
    use chetaev::integrate::Method;
    method_names(|m| m.clone().stiffness_detection_mut().is_some())
}

/// The scene's names of the library's methods that `keep` keeps, "dopri5, dop853, ...".
fn method_names(keep: impl Fn(&chetaev::integrate::AnyMethod) -> bool) -> String {
    use chetaev::integrate::{AnyMethod, Method};
    AnyMethod::all(1.0)
        .iter()
        .filter(|m| keep(m))
        .map(|m| m.info().name.to_lowercase())
        .collect::<Vec<_>>()
        .join(", ")
}

/// The names an output quantity may use: those of the motion, and the recorded multipliers
/// `mu_1..mu_k` and Chetaev force `Phi_<coordinate>` (the columns of `multipliers.csv` and
/// `force.csv`), in the order of [`crate::output::recorded`].
fn quantity_symbols(motion: &Symbols, k: usize) -> Symbols {
    let mut along = motion.clone();
    along.recorded = (1..=k)
        .map(|a| format!("mu_{a}"))
        .chain(motion.coordinates.iter().map(|c| format!("Phi_{c}")))
        .collect();
    along
}

#[cfg(test)]
mod tests {
    use crate::Scene;

    fn with_quantity(name: &str) -> String {
        format!(
            "[model]\ncoordinates = [\"x\"]\nlagrangian = \"0.5*x_dot^2\"\n[initial]\nq = [0.0]\n\
             q_dot = [1.0]\n[solve]\nt_end = 1.0\n[output.quantities]\n{name} = \"2*x\"\n"
        )
    }

    #[test]
    fn a_coordinate_in_a_constant_is_called_a_coordinate() {
        for (from, to) in [
            ("t_end = 1.0", "t_end = \"x\""),
            ("q = [0.0]", "q = [\"x_dot\"]"),
        ] {
            let text = with_quantity("time").replace(from, to);
            let e = Scene::parse(&text, "c.toml").expect_err("no value there");
            assert!(e.to_string().contains("which has no value here"), "{e}");
        }
        let text = format!("[parameters]\na = \"x\"\n{}", with_quantity("time"));
        let e = Scene::parse(&text, "c.toml").expect_err("no value there");
        assert!(e.to_string().contains("'x' is a coordinate"), "{e}");
    }

    #[test]
    fn a_quantity_may_not_take_the_name_of_the_time_column() {
        let e = Scene::parse(&with_quantity("t"), "q.toml").expect_err("t is the time column");
        assert!(e.to_string().contains("time column"), "{e}");
        assert!(Scene::parse(&with_quantity("time"), "q.toml").is_ok());
        assert!(Scene::parse(&with_quantity("_x"), "q.toml").is_ok());
        let e = Scene::parse(&with_quantity("\"1x\""), "q.toml").expect_err("not a name");
        assert!(
            e.to_string().contains("starting with a letter or '_'"),
            "{e}"
        );
    }
}
