//! Cross-crate integration tests live in `tests/`. This library compiles the README's examples
//! as doctests, so the front page cannot drift from the code, and holds the fuzzing harness the
//! CI test and the `cargo fuzz` targets share, and the reference solutions of the
//! forward-dynamics tests (`reference`).

pub mod counting;
pub mod fuzzing;
pub mod reference;

/// A scene both as generated code (`mechanism! { … }`) and as `.mech` text for the interpreter
/// (`const $text: &str`), from one source: `twin! { TEXT, mechanism Name { … } }`
/// (`twin! { pub TEXT, pub mechanism Name { … } }` for a module's scenes).
#[macro_export]
macro_rules! twin {
    ($vis:vis $text:ident, $($scene:tt)*) => {
        ::mechgen_runtime::mechanism! { $($scene)* }
        $vis const $text: &str = stringify!($($scene)*);
    };
}

/// The interpreter running an example scene's `.mech` file (`examples/scenes/FILE`), compiled
/// with the default options; the twin of the generated scene of the same name.
///
/// # Panics
/// If the file cannot be read or does not compile (a test's fixture, not user input).
pub fn example_scene(file: &str) -> mechgen_interp::Interpreted {
    let path = format!("{}/../examples/scenes/{file}", env!("CARGO_MANIFEST_DIR"));
    let source = std::fs::read_to_string(&path).unwrap_or_else(|e| panic!("{path}: {e}"));
    let scene = mechgen::compile(mechgen::Input::Text(&source), &mechgen::Options::default())
        .unwrap_or_else(|e| panic!("{path}: {e}"));
    mechgen_interp::Interpreted::new(&scene)
}

#[doc = include_str!("../../README.md")]
#[cfg(doctest)]
pub struct ReadmeDoctests;

/// Sample times from 0 to 1.5 `toggle` in steps of `typical` times the `fractions` (cycled,
/// all positive), with one exactly at the toggle when `land`: how the toggle tests step a
/// mechanism through a singular configuration at random step lengths.
pub fn toggle_times(toggle: f64, typical: f64, fractions: &[f64], land: bool) -> Vec<f64> {
    let mut times = Vec::new();
    let mut t = 0.0;
    for f in fractions.iter().cycle() {
        t += typical * f;
        if land && t > toggle && times.last().is_none_or(|&last| last < toggle) {
            times.push(toggle);
        }
        times.push(t);
        if t > 1.5 * toggle {
            break;
        }
    }
    times
}
