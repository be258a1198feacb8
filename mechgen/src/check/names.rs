//! The scene's names: every declaration's name unique (they share the generated namespace),
//! references to bodies and points resolved, and for a misspelt name the declared one meant.

use std::collections::HashMap;

use syn::Ident;

use super::Checker;
use crate::model::Point;
use crate::syntax::spec::{PointRef, Spec};

impl Checker {
    /// Every declared name is unique across parameters, bodies, joints, drivers, branches,
    /// loads and markers (they share the generated namespace: fields, accessors, equation,
    /// branch and column names); `t` and `pi` are reserved.
    pub(super) fn check_names(&mut self, spec: &Spec) {
        let mut seen: HashMap<String, &str> = HashMap::new();
        let names = spec
            .params
            .iter()
            .map(|p| (&p.name, "parameter"))
            .chain(spec.bodies.iter().map(|b| (&b.name, "body")))
            .chain(spec.joints.iter().map(|j| (&j.name, "joint")))
            .chain(spec.drivers.iter().map(|d| (&d.name, "driver")))
            .chain(spec.branches.iter().map(|b| (&b.name, "branch")))
            .chain(spec.loads.iter().map(|l| (&l.name, "load")))
            .chain(spec.markers.iter().map(|m| (&m.name, "marker")))
            .chain(spec.points.iter().map(|p| (&p.name, "point")));
        for (name, what) in names {
            let key = name.to_string();
            if key == "t" || key == "pi" {
                let meaning = if key == "t" {
                    "`t` is time"
                } else {
                    "`pi` is π"
                };
                self.errors.push(
                    name.span(),
                    format!("{meaning}; give this {what} another name"),
                );
                continue;
            }
            if let Some(first) = seen.get(&key) {
                self.errors.push(
                    name.span(),
                    format!(
                        "duplicate name `{key}`: a {first} of that name is declared above; \
                         every parameter, body, joint, driver, branch, load, marker and point needs its own name"
                    ),
                );
            } else {
                seen.insert(key, what);
            }
        }
        for (i, body) in spec.bodies.iter().enumerate() {
            self.bodies.entry(body.name.to_string()).or_insert(i);
        }
        for point in &spec.points {
            self.points
                .entry(point.name.to_string())
                .or_insert_with(|| point.point.body.to_string());
        }
        self.classify_parameters(spec);
        if !spec.bodies.iter().any(|b| !b.ground) {
            self.errors.push(
                spec.name.span(),
                "the mechanism has no moving body; declare one with `body NAME near (x, y, angle);`",
            );
        }
    }

    pub(super) fn body(&mut self, name: &Ident) -> Option<usize> {
        let found = self.bodies.get(&name.to_string()).copied();
        if let (None, Some(body)) = (found, self.points.get(&name.to_string())) {
            self.errors.push(
                name.span(),
                format!("`{name}` is a named point (of `{body}`), not a body: name the body here"),
            );
        } else if found.is_none() {
            let known: Vec<String> = {
                let mut v: Vec<(&String, &usize)> = self.bodies.iter().collect();
                v.sort_by_key(|(_, i)| **i);
                v.into_iter().map(|(n, _)| format!("`{n}`")).collect()
            };
            let candidates = self.bodies.keys().map(String::as_str);
            let hint = match did_you_mean(&name.to_string(), candidates) {
                Some(close) => format!("did you mean `{close}`? "),
                None => String::new(),
            };
            self.errors.push(
                name.span(),
                format!(
                    "unknown body `{name}`; {hint}declared bodies are {}",
                    if known.is_empty() {
                        "none".to_owned()
                    } else {
                        known.join(", ")
                    }
                ),
            );
        }
        found
    }

    pub(super) fn point(&mut self, p: &PointRef) -> Option<Point> {
        let body = self.body(&p.body)?;
        let local = match &p.local {
            Some(xy) => [self.length(&xy[0]), self.length(&xy[1])],
            None => [self.arena.zero(), self.arena.zero()],
        };
        Some(Point { body, local })
    }
}

/// The candidate closest to a misspelt `name`, if it is plausibly a typo (edit distance ≤ 2 and
/// less than half the name). Public for the command line's suggestions.
pub fn did_you_mean<'a>(name: &str, candidates: impl Iterator<Item = &'a str>) -> Option<&'a str> {
    candidates
        .map(|c| (edit_distance(name, c), c))
        .filter(|&(d, _)| d <= 2 && 2 * d < name.chars().count().max(2))
        .min()
        .map(|(_, c)| c)
}

/// Levenshtein distance (names are short; the quadratic table is fine).
pub(super) fn edit_distance(a: &str, b: &str) -> usize {
    let b: Vec<char> = b.chars().collect();
    let mut row: Vec<usize> = (0..=b.len()).collect();
    for (i, ca) in a.chars().enumerate() {
        let mut diagonal = row[0];
        row[0] = i + 1;
        for (j, &cb) in b.iter().enumerate() {
            let substitution = diagonal + usize::from(ca != cb);
            diagonal = row[j + 1];
            row[j + 1] = substitution.min(row[j] + 1).min(row[j + 1] + 1);
        }
    }
    row[b.len()]
}
