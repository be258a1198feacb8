//! `--set NAME=VALUE`: parameter overrides checked against the scene (a name it does not
//! declare is a bad command line, with the closest declared name suggested) and set all or
//! none.

use mechgen_interp::Interpreted;
use mechgen_runtime::Mechanism;

use crate::args;
use crate::failure::{Failure, failed};

/// Sets the overrides on `mechanism` for `mechgen COMMAND`: an unknown name is a usage error
/// of that command (exit status 2), a value the scene refuses a failure (exit status 1).
pub(crate) fn apply(
    mechanism: &mut Interpreted,
    sets: &[(String, f64)],
    command: &str,
) -> Result<(), Failure> {
    apply_sets(mechanism, sets).map_err(|error| match error {
        SetError::Unknown(message) => {
            Failure::Usage(args::usage_error(command, message).render().to_string())
        }
        SetError::Invalid(message) => failed(message),
    })
}

/// Why `--set` overrides were refused.
#[derive(Debug, Clone, PartialEq, Eq)]
pub(crate) enum SetError {
    /// A name the scene does not declare: a bad command line (exit status 2).
    Unknown(String),
    /// A value the scene refuses.
    Invalid(String),
}

impl core::fmt::Display for SetError {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        match self {
            SetError::Unknown(message) | SetError::Invalid(message) => f.write_str(message),
        }
    }
}

/// Sets the `--set` overrides on `mechanism`, all or none.
///
/// # Errors
/// A message naming the bad override, suggesting the declared name closest to a misspelt one
/// and listing the parameters the scene declares.
pub(crate) fn apply_sets(
    mechanism: &mut Interpreted,
    sets: &[(String, f64)],
) -> Result<(), SetError> {
    // Checked before any is set, so that the list in the message shows the scene's defaults.
    for (name, value) in sets {
        let names: Vec<&str> = (0..mechanism.parameter_count())
            .filter_map(|i| mechanism.parameter_name(i))
            .collect();
        if mechanism.derived_parameter_names().contains(name) {
            return Err(SetError::Unknown(format!(
                "`--set {name}={value}`: `{name}` is a derived parameter, computed from others \
                 (`mechgen check FILE` shows it): set the parameters it is computed from; {}",
                declared_parameters(mechanism)
            )));
        }
        if !names.contains(&name.as_str()) {
            let hint = mechgen::check::did_you_mean(name, names.iter().copied())
                .map(|close| format!("did you mean `{close}`? "))
                .unwrap_or_default();
            return Err(SetError::Unknown(format!(
                "`--set {name}={value}`: the scene declares no parameter `{name}`; {hint}{}",
                declared_parameters(mechanism)
            )));
        }
        if !value.is_finite() {
            return Err(SetError::Invalid(format!(
                "`--set {name}={value}`: parameter values must be finite numbers; {}",
                declared_parameters(mechanism)
            )));
        }
    }
    for (name, value) in sets {
        mechanism
            .set_parameter(name, *value)
            .map_err(|error| SetError::Invalid(format!("`--set {name}={value}`: {error}")))?;
    }
    Ok(())
}

fn declared_parameters(mechanism: &Interpreted) -> String {
    let list: Vec<String> = (0..mechanism.parameter_count())
        .filter_map(|i| {
            let name = mechanism.parameter_name(i)?;
            let value = mechanism.parameter(i)?;
            Some(format!("`{name}` (default {value})"))
        })
        .collect();
    if list.is_empty() {
        "the scene declares no parameters, so `--set` cannot be used with it".to_owned()
    } else {
        format!("declared parameters: {}", list.join(", "))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn overrides_name_the_declared_parameters() {
        let scene = mechgen::compile(
            mechgen::Input::Text(
                "mechanism M { param w = 3; ground g at (0, 0, 0); body b near (0, 0, 0);
             joint j: revolute(g, b); driver d: angle(b) = w * t; }",
            ),
            &mechgen::Options::default(),
        )
        .expect("compiles");
        let mut mechanism = Interpreted::new(&scene);
        assert!(apply_sets(&mut mechanism, &[("w".into(), 5.0)]).is_ok());
        assert_eq!(mechanism.parameter(0), Some(5.0));
        let mut fresh = Interpreted::new(&scene);
        let sets = [("w".into(), 7.0), ("v".into(), 1.0)];
        let unknown = apply_sets(&mut fresh, &sets).unwrap_err().to_string();
        assert!(unknown.contains("no parameter `v`"), "{unknown}");
        assert!(unknown.contains("`w` (default 3)"), "{unknown}");
        assert_eq!(fresh.parameter(0), Some(3.0), "all or none");
        let infinite = apply_sets(&mut mechanism, &[("w".into(), f64::INFINITY)])
            .unwrap_err()
            .to_string();
        assert!(infinite.contains("finite"), "{infinite}");
    }
}
