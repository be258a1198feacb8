//! Building a scene in Rust code: for scenes too big to write by hand (chains, arrays of
//! identical linkages), typically from a `build.rs` that writes the generated code into
//! `OUT_DIR` for the crate to `include!`.
//!
//! [`SceneBuilder`] produces the spec *text* of [`crate::syntax::parse`]'s grammar, so a built
//! scene goes through exactly the pipeline a hand-written one does and every check applies
//! (unknown bodies, duplicate names, the Gruebler degree-of-freedom count, …). Names, numbers
//! and expressions are checked early, as each statement is added; those errors and the
//! checker's are returned together as [`Errors`].
//!
//! ```
//! use mechgen::builder::SceneBuilder;
//!
//! let mut scene = SceneBuilder::new("Pendulum");
//! scene.doc("A pendulum swung by its angle.");
//! scene.param("omega", 2.0).item_doc("Swing speed (rad/s).");
//! scene.ground("frame", [0.0, 0.0, 0.0]);
//! scene.body("bob", [1.0, 0.0, 0.0]);
//! scene.revolute("pivot", "frame", ("bob", [-1.0, 0.0]));
//! scene.driver_angle("swing", "bob", "omega * t");
//! let text = scene.build().expect("a valid scene");
//! assert!(text.contains("joint pivot: revolute(frame, bob @ (-1.0, 0.0));"));
//! let code = scene.expand(&mechgen::CodegenOptions::default()).expect("expands");
//! assert!(code.to_string().contains("struct Pendulum"));
//! ```
//!
//! **Error locations.** Errors from a built scene carry no useful span: there is no source file
//! to point into. Their messages name the statement (and the checker's messages name the bodies,
//! joints and drivers involved), which is what to look for in the code that built the scene;
//! [`SceneBuilder::build`]'s text can also be written to a `.mech` file and checked with the CLI.
//!
//! **From `build.rs`.** [`SceneBuilder::write_to_out_dir`] writes the generated items
//! unformatted, one statement per line ([`source_text`]); the including crate (which depends on
//! `mechgen-runtime`) writes `include!(concat!(env!("OUT_DIR"), "/scene.rs"));` at item level.
//! The line breaks matter (rustc is slow on very long lines); formatting with prettyplease (the
//! `pretty` feature, `SceneBuilder::write_pretty_to`) adds nothing for rustc and costs more
//! than the expansion itself on large scenes.
//!
//! This file is the builder's API; its arguments ([`Value`], [`Point`]) are in `values`, the
//! token formatter ([`source_text`]) in `text`, the file writing in `write`, and the `free`
//! statements of forward dynamics in `free`.

mod free;
mod text;
mod values;
mod write;

pub use crate::syntax::spec::{Product, Sign};
pub use text::source_text;
pub use values::{Point, Value};
pub use write::WriteError;

use std::fmt::Write as _;

use proc_macro2::{Span, TokenStream};

use crate::emit::CodegenOptions;
use crate::error::Errors;
use crate::model::Outputs;

/// One statement of the scene, already rendered, with its doc lines.
struct Item {
    docs: Vec<String>,
    text: String,
}

/// Assembles a scene statement by statement; see the [module documentation](self).
///
/// Methods take `&mut self` and return it, so calls chain and also sit naturally in loops.
/// Nothing panics: a bad name, a non-finite number or an expression that does not parse is
/// recorded and reported by [`build`](Self::build) (and everything that calls it) together with
/// every other error.
pub struct SceneBuilder {
    name: String,
    public: bool,
    docs: Vec<String>,
    items: Vec<Item>,
    /// The `outputs` statement, if any (the grammar's default is all three levels).
    outputs: Option<Outputs>,
    /// Problems found while adding statements, reported by `build`.
    errors: Vec<String>,
}

impl SceneBuilder {
    /// A new, empty, `pub` mechanism called `name` (an identifier, UpperCamelCase by convention:
    /// it names the generated struct).
    pub fn new(name: &str) -> Self {
        let mut builder = SceneBuilder {
            name: name.to_owned(),
            public: true,
            docs: Vec::new(),
            items: Vec::new(),
            outputs: None,
            errors: Vec::new(),
        };
        builder.check_name(name, "the mechanism");
        builder
    }

    /// Whether the generated items are `pub` (the default) or private to the including module.
    pub fn public(&mut self, public: bool) -> &mut Self {
        self.public = public;
        self
    }

    /// Adds a doc line (or several, split at line breaks) to the mechanism: carried onto the
    /// generated struct.
    pub fn doc(&mut self, text: &str) -> &mut Self {
        self.docs.extend(doc_lines(text));
        self
    }

    /// Adds a doc line (or several) to the most recently added statement: a parameter's becomes
    /// its field's documentation, a body's its accessor's.
    pub fn item_doc(&mut self, text: &str) -> &mut Self {
        match self.items.last_mut() {
            Some(item) => item.docs.extend(doc_lines(text)),
            None => self.errors.push(format!(
                "`item_doc({text:?})` was called before any parameter, body, joint or driver was \
                 added: it documents the statement added just before it (use `doc` for the \
                 mechanism)"
            )),
        }
        self
    }

    /// `outputs …;`: which levels the generated code computes, up to and including `outputs`
    /// (the default, without this call, is all it can: the three kinematic levels, and forces
    /// when the scene has masses or loads). A later call replaces an earlier one.
    pub fn outputs(&mut self, outputs: Outputs) -> &mut Self {
        self.outputs = Some(outputs);
        self
    }

    /// `param NAME = DEFAULT;`: a run-time parameter (a field of the generated struct) with its
    /// default, a number or a constant expression; or, when the expression names other
    /// parameters, a derived parameter computed from them (see the grammar).
    pub fn param(&mut self, name: &str, default: impl Into<Value>) -> &mut Self {
        let what = format!("parameter `{name}`");
        self.check_name(name, &what);
        let default = self.value(default.into(), &what);
        self.push(format!("param {name} = {default};"))
    }

    /// `ground NAME at (x, y, angle);`: a fixed body at `pose`.
    pub fn ground(&mut self, name: &str, pose: [f64; 3]) -> &mut Self {
        let what = format!("ground body `{name}`");
        self.check_name(name, &what);
        let pose = self.tuple(&pose, &what);
        self.push(format!("ground {name} at {pose};"))
    }

    /// `body NAME near (x, y, angle);`: a moving body with its initial guess. Bodies are
    /// numbered in the order they are added (the order of q).
    pub fn body(&mut self, name: &str, guess: [f64; 3]) -> &mut Self {
        let what = format!("body `{name}`");
        self.check_name(name, &what);
        let guess = self.tuple(&guess, &what);
        self.push(format!("body {name} near {guess};"))
    }

    /// `body NAME near (x, y, angle) mass M inertia J centre (cx, cy);`: a moving body with its
    /// mass, its moment of inertia about the centre of mass, and the centre in its frame (for a
    /// scene that computes forces).
    pub fn body_with_mass(
        &mut self,
        name: &str,
        guess: [f64; 3],
        mass: impl Into<Value>,
        inertia: impl Into<Value>,
        centre: [f64; 2],
    ) -> &mut Self {
        let what = format!("body `{name}`");
        self.check_name(name, &what);
        let guess = self.tuple(&guess, &what);
        let (mass, inertia) = (
            self.value(mass.into(), &what),
            self.value(inertia.into(), &what),
        );
        let centre = self.tuple(&centre, &what);
        self.push(format!(
            "body {name} near {guess} mass {mass} inertia {inertia} centre {centre};"
        ))
    }

    /// `gravity (gx, gy);`: the acceleration of gravity in world axes.
    pub fn gravity(&mut self, gravity: [f64; 2]) -> &mut Self {
        let gravity = self.tuple(&gravity, "gravity");
        self.push(format!("gravity {gravity};"))
    }

    /// `load NAME: force(point) = (fx, fy);` in world axes, or with `local` in the body's axes
    /// (`local_force`); the components may use `t` and parameters.
    pub fn force(
        &mut self,
        name: &str,
        point: impl Into<Point>,
        [fx, fy]: [Value; 2],
        local: bool,
    ) -> &mut Self {
        let what = format!("load `{name}`");
        self.check_name(name, &what);
        let point = self.point(point.into(), &what);
        let (fx, fy) = (self.value(fx, &what), self.value(fy, &what));
        let kind = if local { "local_force" } else { "force" };
        self.push(format!("load {name}: {kind}({point}) = ({fx}, {fy});"))
    }

    /// `load NAME: torque(body) = value;`: a torque on a moving body.
    pub fn torque(&mut self, name: &str, body: &str, value: impl Into<Value>) -> &mut Self {
        let what = format!("load `{name}`");
        self.check_name(name, &what);
        self.check_name(body, &format!("the body of {what}"));
        let value = self.value(value.into(), &what);
        self.push(format!("load {name}: torque({body}) = {value};"))
    }

    /// `load NAME: spring(a, b, stiffness k, length L, damping c);`: a linear spring-damper
    /// between two points (a zero stiffness or damping leaves that part out).
    pub fn spring(
        &mut self,
        name: &str,
        a: impl Into<Point>,
        b: impl Into<Point>,
        [stiffness, length, damping]: [Value; 3],
    ) -> &mut Self {
        let what = format!("load `{name}`");
        self.check_name(name, &what);
        let (a, b) = (self.point(a.into(), &what), self.point(b.into(), &what));
        let [stiffness, length, damping] =
            [stiffness, length, damping].map(|v| self.value(v, &what));
        self.push(format!(
            "load {name}: spring({a}, {b}, stiffness {stiffness}, length {length}, damping \
             {damping});"
        ))
    }

    /// `joint NAME: revolute(a, b);`: points `a` and `b` coincide (2 equations).
    pub fn revolute(&mut self, name: &str, a: impl Into<Point>, b: impl Into<Point>) -> &mut Self {
        let what = format!("joint `{name}`");
        self.check_name(name, &what);
        let (a, b) = (self.point(a.into(), &what), self.point(b.into(), &what));
        self.push(format!("joint {name}: revolute({a}, {b});"))
    }

    /// `joint NAME: prismatic(a, b, along (ux, uy));`: `b`'s point slides along the axis through
    /// `a`'s point, `axis` in `a`'s frame, and the two bodies keep their relative angle
    /// (2 equations).
    pub fn prismatic(
        &mut self,
        name: &str,
        a: impl Into<Point>,
        b: impl Into<Point>,
        axis: [f64; 2],
    ) -> &mut Self {
        let what = format!("joint `{name}`");
        self.check_name(name, &what);
        let (a, b) = (self.point(a.into(), &what), self.point(b.into(), &what));
        let axis = self.tuple(&axis, &what);
        self.push(format!("joint {name}: prismatic({a}, {b}, along {axis});"))
    }

    /// `joint NAME: distance(a, b, length);`: the points stay `length` apart (1 equation).
    pub fn distance(
        &mut self,
        name: &str,
        a: impl Into<Point>,
        b: impl Into<Point>,
        length: impl Into<Value>,
    ) -> &mut Self {
        let what = format!("joint `{name}`");
        self.check_name(name, &what);
        let (a, b) = (self.point(a.into(), &what), self.point(b.into(), &what));
        let length = self.value(length.into(), &what);
        self.push(format!("joint {name}: distance({a}, {b}, {length});"))
    }

    /// `driver NAME: angle(body) = value;`: the body's angle follows `value` (may use `t`).
    pub fn driver_angle(&mut self, name: &str, body: &str, value: impl Into<Value>) -> &mut Self {
        let body = self.body_ref(body, name);
        self.driver(name, format!("angle({body})"), value)
    }

    /// `driver NAME: relative_angle(a, b) = value;`: θ_b − θ_a follows `value`.
    pub fn driver_relative_angle(
        &mut self,
        name: &str,
        a: &str,
        b: &str,
        value: impl Into<Value>,
    ) -> &mut Self {
        let (a, b) = (self.body_ref(a, name), self.body_ref(b, name));
        self.driver(name, format!("relative_angle({a}, {b})"), value)
    }

    /// `driver NAME: x(point) = value;`: the point's global x follows `value`.
    pub fn driver_x(
        &mut self,
        name: &str,
        point: impl Into<Point>,
        value: impl Into<Value>,
    ) -> &mut Self {
        let point = self.point(point.into(), &format!("driver `{name}`"));
        self.driver(name, format!("x({point})"), value)
    }

    /// `driver NAME: y(point) = value;`: the point's global y follows `value`.
    pub fn driver_y(
        &mut self,
        name: &str,
        point: impl Into<Point>,
        value: impl Into<Value>,
    ) -> &mut Self {
        let point = self.point(point.into(), &format!("driver `{name}`"));
        self.driver(name, format!("y({point})"), value)
    }

    /// `driver NAME: travel(joint) = value;`: the travel along a prismatic joint follows `value`.
    pub fn driver_travel(&mut self, name: &str, joint: &str, value: impl Into<Value>) -> &mut Self {
        let what = format!("driver `{name}`");
        self.check_name(joint, &format!("the joint of {what}"));
        self.driver(name, format!("travel({joint})"), value)
    }

    /// `branch NAME: cross(u.0 -> u.1, v.0 -> v.1) > 0;` (or `dot(…)`, or `< 0`): a branch
    /// invariant, the product of two world vectors between body-fixed points whose sign the
    /// solver keeps (see [`crate::syntax::parse`]).
    ///
    /// ```
    /// # use mechgen::builder::{Product, SceneBuilder, Sign};
    /// # let mut scene = SceneBuilder::new("FourBar");
    /// scene.branch(
    ///     "open",
    ///     Product::Cross,
    ///     (("coupler", [120.0, 0.0]), "coupler"),
    ///     (("rocker", [80.0, 0.0]), "rocker"),
    ///     Sign::Positive,
    /// );
    /// ```
    pub fn branch(
        &mut self,
        name: &str,
        product: Product,
        u: (impl Into<Point>, impl Into<Point>),
        v: (impl Into<Point>, impl Into<Point>),
        sign: Sign,
    ) -> &mut Self {
        let what = format!("branch `{name}`");
        self.check_name(name, &what);
        let [u0, u1, v0, v1] =
            [u.0.into(), u.1.into(), v.0.into(), v.1.into()].map(|p| self.point(p, &what));
        let comparison = match sign {
            Sign::Positive => ">",
            Sign::Negative => "<",
        };
        self.push(format!(
            "branch {name}: {}({u0} -> {u1}, {v0} -> {v1}) {comparison} 0;",
            product.name()
        ))
    }

    /// The scene as spec text (the grammar of [`crate::syntax::parse`]), ready for
    /// [`crate::compile`] or a `.mech` file.
    ///
    /// # Errors
    /// Every invalid name, non-finite number and unparsable expression added, together. The
    /// scene's semantics (unknown bodies, degrees of freedom, …) are checked by
    /// [`expand`](Self::expand), not here.
    pub fn build(&self) -> Result<String, Errors> {
        if !self.errors.is_empty() {
            let mut errors = Errors::default();
            for message in &self.errors {
                errors.push(Span::call_site(), message);
            }
            return Err(errors);
        }
        // About 60 bytes a statement; one allocation for the whole text.
        let mut text = String::with_capacity(64 * (self.items.len() + 2));
        for line in &self.docs {
            let _ = writeln!(text, "///{line}");
        }
        let vis = if self.public { "pub " } else { "" };
        let _ = writeln!(text, "{vis}mechanism {} {{", self.name);
        for item in &self.items {
            for line in &item.docs {
                let _ = writeln!(text, "    ///{line}");
            }
            let _ = writeln!(text, "    {}", item.text);
        }
        if let Some(outputs) = self.outputs {
            // Every level up to this one, as the grammar requires: `positions, velocities`.
            let levels = Outputs::ALL.iter().position(|&o| o == outputs).unwrap_or(2);
            let names = Outputs::NAMES.get(..=levels).unwrap_or(&Outputs::NAMES);
            let _ = writeln!(text, "    outputs {};", names.join(", "));
        }
        text.push_str("}\n");
        Ok(text)
    }

    /// The generated Rust items: [`build`](Self::build), then [`crate::expand`] with `options`,
    /// the text read without size and count limits (a program wrote it).
    ///
    /// # Errors
    /// As [`build`](Self::build), then every error of the checker (see the module
    /// documentation on their locations).
    pub fn expand(&self, options: &CodegenOptions) -> Result<TokenStream, Errors> {
        let options = crate::Options {
            limits: crate::Limits::UNBOUNDED_SIZE,
            codegen: *options,
        };
        crate::expand(crate::Input::Text(&self.build()?), &options)
    }

    /// Records `text` as the next statement.
    fn push(&mut self, text: String) -> &mut Self {
        self.items.push(Item {
            docs: Vec::new(),
            text,
        });
        self
    }

    fn driver(&mut self, name: &str, kind: String, value: impl Into<Value>) -> &mut Self {
        let what = format!("driver `{name}`");
        self.check_name(name, &what);
        let value = self.value(value.into(), &what);
        self.push(format!("driver {name}: {kind} = {value};"))
    }

    /// A body named by `driver`, checked as an identifier; returned as given.
    fn body_ref<'a>(&mut self, body: &'a str, driver: &str) -> &'a str {
        self.check_name(body, &format!("a body of driver `{driver}`"));
        body
    }

    /// Records an error unless `name` is one identifier the grammar accepts (not a Rust
    /// keyword, not a raw identifier, not `_`), and not `t`, which means time.
    fn check_name(&mut self, name: &str, what: &str) {
        if name == "t" {
            self.errors
                .push(format!("{what}: `t` is time; choose another name"));
            return;
        }
        // Exactly what the parser will accept: one identifier token, nothing else.
        let valid = !name.starts_with("r#") && syn::parse_str::<syn::Ident>(name).is_ok();
        if !valid {
            self.errors.push(format!(
                "{what}: {name:?} is not a valid name; names are identifiers such as `arm_0` \
                 (letters, digits and `_`, not starting with a digit, not a Rust keyword)"
            ));
        }
    }

    /// `value` rendered in the grammar, or a placeholder after recording why it can't be.
    fn value(&mut self, value: Value, what: &str) -> String {
        match value {
            Value::Number(x) => self.number(x, what),
            Value::Expr(source) => match expression(&source) {
                Ok(text) => text,
                Err(message) => {
                    self.errors
                        .push(format!("{what}: expression {source:?}: {message}"));
                    String::from("0.0")
                }
            },
        }
    }

    fn number(&mut self, x: f64, what: &str) -> String {
        if x.is_finite() {
            // `{:?}` is the shortest representation that reads back to the same f64, and
            // always a float literal the grammar accepts (`1.0`, `-2.5`, `1e-7`).
            format!("{x:?}")
        } else {
            self.errors.push(format!(
                "{what}: {x} is not a finite number; every value in a scene must be finite"
            ));
            String::from("0.0")
        }
    }

    fn tuple(&mut self, values: &[f64], what: &str) -> String {
        let parts: Vec<String> = values.iter().map(|&x| self.number(x, what)).collect();
        format!("({})", parts.join(", "))
    }

    fn point(&mut self, point: Point, what: &str) -> String {
        self.check_name(&point.body, &format!("a point of {what}"));
        match point.local {
            None => point.body,
            Some(local) => format!("{} @ {}", point.body, self.tuple(&local, what)),
        }
    }
}

/// `source` checked as one expression of the grammar and re-rendered from its tokens, so that a
/// comment in it cannot swallow the rest of the statement.
fn expression(source: &str) -> Result<String, String> {
    let tokens: TokenStream = source.parse().map_err(|e| format!("{e}"))?;
    if tokens.is_empty() {
        return Err("empty; write a number or an expression".to_owned());
    }
    // The size limits first: the expression parser recurses on nesting.
    crate::syntax::limits::check(&tokens).map_err(|e| e.to_string())?;
    syn::parse2::<crate::syntax::spec::Expr>(tokens.clone()).map_err(|e| e.to_string())?;
    Ok(tokens.to_string())
}

/// Doc comment lines for `text`: one per line, each starting with a space so that `///` followed
/// by text beginning with `/` stays a doc comment rather than becoming a plain `////` comment.
fn doc_lines(text: &str) -> impl Iterator<Item = String> + '_ {
    text.split(['\n', '\r']).map(|line| {
        if line.is_empty() {
            String::new()
        } else {
            format!(" {line}")
        }
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A crank-slider: 3 moving bodies, 8 joint equations, 1 driver.
    fn slider_crank() -> SceneBuilder {
        let mut scene = SceneBuilder::new("SliderCrank");
        scene.doc("A slider-crank.\n/ line starting with a slash");
        scene.param("omega", 2.0).item_doc("Crank speed (rad/s).");
        scene.ground("frame", [0.0, 0.0, 0.0]);
        scene.body("crank", [0.5, 0.0, 0.0]);
        scene.body("rod", [2.0, 0.0, 0.0]);
        scene.body("slider", [3.0, 0.0, 0.0]);
        scene.revolute("bearing", "frame", ("crank", [-0.5, 0.0]));
        scene.revolute("crank_pin", ("crank", [0.5, 0.0]), ("rod", [-1.0, 0.0]));
        scene.revolute("wrist", ("rod", [1.0, 0.0]), "slider");
        scene.prismatic("guide", "frame", "slider", [1.0, 0.0]);
        scene.driver_angle("spin", "crank", "omega * t // a comment cannot eat the `;`");
        scene
    }

    #[test]
    fn text_round_trips_through_the_compiler() {
        let text = slider_crank().build().unwrap_or_else(|e| panic!("{e}"));
        assert!(
            text.starts_with("/// A slider-crank.\n/// / line starting"),
            "{text}"
        );
        assert!(
            text.contains("    /// Crank speed (rad/s).\n    param omega = 2.0;"),
            "{text}"
        );
        assert!(text.contains("joint crank_pin: revolute(crank @ (0.5, 0.0), rod @ (-1.0, 0.0));"));
        assert!(
            text.contains("driver spin: angle(crank) = omega * t;"),
            "{text}"
        );
        let scene = crate::compile(crate::Input::Text(&text), &crate::Options::default())
            .unwrap_or_else(|e| panic!("{e}\n{text}"));
        assert_eq!(scene.model.dim(), 12);
        let code = slider_crank()
            .expand(&CodegenOptions::default())
            .unwrap_or_else(|e| panic!("{e}"))
            .to_string();
        assert!(code.contains("struct SliderCrank"));
    }

    #[test]
    fn branches_are_written_in_the_grammar() {
        let mut scene = slider_crank();
        scene
            .branch(
                "outboard",
                Product::Dot,
                ("frame", "slider"),
                (("rod", [-1.0, 0.0]), ("rod", [1.0, 0.0])),
                Sign::Positive,
            )
            .item_doc("The slider stays right of the crank.")
            .branch(
                "up",
                Product::Cross,
                ("frame", ("crank", [0.5, 0.0])),
                ("frame", "slider"),
                Sign::Negative,
            );
        let text = scene.build().unwrap_or_else(|e| panic!("{e}"));
        assert!(
            text.contains(
                "    /// The slider stays right of the crank.\n    branch outboard: \
                 dot(frame -> slider, rod @ (-1.0, 0.0) -> rod @ (1.0, 0.0)) > 0;"
            ),
            "{text}"
        );
        assert!(
            text.contains("branch up: cross(frame -> crank @ (0.5, 0.0), frame -> slider) < 0;"),
            "{text}"
        );
        let compiled = crate::compile(crate::Input::Text(&text), &crate::Options::default())
            .unwrap_or_else(|e| panic!("{e}\n{text}"));
        assert_eq!(compiled.model.branches.len(), 2);
        assert_eq!(compiled.kinematics.branches.len(), 2);
        let mut bad = slider_crank();
        bad.branch(
            "t",
            Product::Dot,
            ("frame", "b-c"),
            ("frame", "slider"),
            Sign::Positive,
        );
        let messages = bad.build().expect_err("errors").messages();
        assert_eq!(messages.len(), 2, "{messages:#?}");
    }

    #[test]
    fn masses_gravity_and_loads_round_trip() {
        let mut scene = slider_crank();
        scene
            .body_with_mass("weight", [3.0, -1.0, 0.0], 2.0, "0.5 * omega", [0.1, 0.0])
            .revolute("hang", "slider", ("weight", [0.0, 1.0]))
            .driver_relative_angle("sway", "slider", "weight", "0.1 * sin(t)")
            .gravity([0.0, -9.81])
            .force(
                "push",
                ("slider", [0.0, 0.5]),
                ["sin(t)".into(), 0.0.into()],
                false,
            )
            .force("lift", "weight", [0.0.into(), 1.0.into()], true)
            .torque("brake", "crank", "-0.1 * t")
            .spring(
                "coil",
                "frame",
                "weight",
                [10.0.into(), 2.0.into(), 0.5.into()],
            );
        let text = scene.build().unwrap_or_else(|e| panic!("{e}"));
        assert!(
            text.contains(
                "body weight near (3.0, -1.0, 0.0) mass 2.0 inertia 0.5 * omega centre (0.1, 0.0);"
            ),
            "{text}"
        );
        assert!(text.contains("load lift: local_force(weight) = (0.0, 1.0);"));
        assert!(text.contains(
            "load coil: spring(frame, weight, stiffness 10.0, length 2.0, damping 0.5);"
        ));
        let compiled = crate::compile(crate::Input::Text(&text), &crate::Options::default())
            .unwrap_or_else(|e| panic!("{e}\n{text}"));
        assert_eq!(compiled.model.outputs, crate::model::Outputs::Forces);
        assert_eq!(compiled.model.loads.len(), 4);
        assert!(compiled.forces.is_some());
    }

    #[test]
    fn outputs_are_written_as_the_grammar_lists_them() {
        for (outputs, line) in [
            (Outputs::Positions, "outputs positions;"),
            (Outputs::Velocities, "outputs positions, velocities;"),
            (
                Outputs::Accelerations,
                "outputs positions, velocities, accelerations;",
            ),
        ] {
            let mut scene = slider_crank();
            scene.outputs(outputs);
            let text = scene.build().unwrap_or_else(|e| panic!("{e}"));
            assert!(text.contains(line), "{text}");
            let compiled = crate::compile(crate::Input::Text(&text), &crate::Options::default())
                .unwrap_or_else(|e| panic!("{e}\n{text}"));
            assert_eq!(compiled.model.outputs, outputs);
        }
    }

    #[test]
    fn source_text_has_short_lines_and_the_same_tokens() {
        let code = slider_crank()
            .expand(&CodegenOptions::default())
            .unwrap_or_else(|e| panic!("{e}"));
        let text = source_text(code.clone());
        let longest = text.lines().map(str::len).max().unwrap_or(0);
        let line = text.lines().max_by_key(|l| l.len()).unwrap_or("");
        assert!(longest < 200, "a line of {longest} bytes: {line}");
        let reparsed: TokenStream = text.parse().unwrap_or_else(|e| panic!("{e}\n{text}"));
        assert_eq!(reparsed.to_string(), code.to_string());
        assert!(text.contains("[& 'static str ; 12 ]"), "{text}");
    }

    #[test]
    fn numbers_round_trip_exactly() {
        let values = [0.1, -2.5, 1e-7, 1e300, f64::MIN_POSITIVE, 1.0 / 3.0, -0.0];
        let mut scene = SceneBuilder::new("Numbers");
        for (i, &x) in values.iter().enumerate() {
            scene.param(&format!("p{i}"), x);
        }
        scene.ground("frame", [0.0, 0.0, 0.0]);
        scene.body("b", [0.0, 0.0, 0.0]);
        scene.revolute("pin", "frame", "b");
        scene.driver_angle("d", "b", "t");
        let text = scene.build().unwrap_or_else(|e| panic!("{e}"));
        let compiled = crate::compile(crate::Input::Text(&text), &crate::Options::default())
            .unwrap_or_else(|e| panic!("{e}\n{text}"));
        for (param, &x) in compiled.model.params.iter().zip(&values) {
            // Bit-exact, except that the checker folds `-0.0` to `0.0` (equal as numbers).
            assert!(param.default == x && (x == 0.0 || param.default.to_bits() == x.to_bits()));
        }
    }

    #[test]
    fn derived_parameters_are_built_from_expressions() {
        let mut scene = SceneBuilder::new("Derived");
        scene
            .param("a", 3.0)
            .param("b", 4.0)
            .param("c", "sqrt(a^2 + b^2)");
        scene.ground("frame", [0.0, 0.0, 0.0]);
        scene.body("b1", [0.0, 0.0, 0.0]);
        scene.revolute("pin", "frame", ("b1", [0.0, 0.0]));
        scene.driver_angle("d", "b1", "c * t");
        let text = scene.build().unwrap_or_else(|e| panic!("{e}"));
        let compiled = crate::compile(crate::Input::Text(&text), &crate::Options::default())
            .unwrap_or_else(|e| panic!("{e}\n{text}"));
        let model = &compiled.model;
        assert_eq!(model.params.len(), 2);
        assert_eq!(model.derived.len(), 1);
        let env = crate::expr::tape::Env {
            params: vec![3.0, 4.0],
            ..Default::default()
        };
        assert_eq!(
            crate::expr::tape::eval(&model.arena, model.derived[0].value, &env),
            5.0
        );
    }

    #[test]
    fn bad_names_numbers_and_expressions_are_collected() {
        let mut scene = SceneBuilder::new("9Lives");
        scene
            .param("fn", 1.0)
            .param("t", 1.0)
            .param("ok", f64::NAN)
            .ground("r#raw", [0.0, f64::INFINITY, 0.0])
            .body("two words", [0.0; 3])
            .body("_", [0.0; 3])
            .revolute("pin", ("a-b", [0.0, 0.0]), "b")
            .driver_angle("d", "b", "omega * ")
            .driver_angle("e", "b", "1; body x near (0, 0, 0)")
            .driver_angle("f", "b", "")
            .driver_angle("g", "b", format!("{}t{}", "(".repeat(100), ")".repeat(100)));
        let messages = scene.build().expect_err("errors").messages();
        let expected = [
            "the mechanism: \"9Lives\" is not a valid name",
            "parameter `fn`: \"fn\" is not a valid name",
            "parameter `t`: `t` is time",
            "parameter `ok`: NaN is not a finite number",
            "ground body `r#raw`: \"r#raw\" is not a valid name",
            "ground body `r#raw`: inf is not a finite number",
            "body `two words`: \"two words\" is not a valid name",
            "body `_`: \"_\" is not a valid name",
            "a point of joint `pin`: \"a-b\" is not a valid name",
            "driver `d`: expression \"omega * \"",
            "driver `e`: expression \"1; body x near (0, 0, 0)\"",
            "driver `f`: expression \"\": empty",
            "nested more than 64 levels",
        ];
        assert_eq!(messages.len(), expected.len(), "{messages:#?}");
        for (message, expected) in messages.iter().zip(expected) {
            assert!(message.contains(expected), "{message:?} lacks {expected:?}");
        }
        let orphan = SceneBuilder::new("M").item_doc("no item yet").build();
        assert!(
            orphan
                .expect_err("error")
                .to_string()
                .contains("before any parameter")
        );
    }

    #[test]
    fn the_checker_reports_built_scenes_too() {
        // The driver is forgotten: the Gruebler count says 1 DOF, 0 drivers.
        let mut scene = SceneBuilder::new("Loose");
        scene.ground("frame", [0.0; 3]).body("crank", [0.0; 3]);
        scene.revolute("pin", "frame", "crank");
        scene.revolute("typo", "frame", "crnak");
        let messages = scene
            .expand(&CodegenOptions::default())
            .expect_err("errors")
            .messages();
        assert!(
            messages.iter().any(|m| m.contains("unknown body `crnak`")),
            "{messages:#?}"
        );
        let mut scene = SceneBuilder::new("Loose");
        scene.ground("frame", [0.0; 3]).body("crank", [0.0; 3]);
        scene.revolute("pin", "frame", "crank");
        let messages = scene
            .expand(&CodegenOptions::default())
            .expect_err("errors")
            .messages();
        assert!(
            messages
                .iter()
                .any(|m| m.contains("1 degree of freedom but 0 drivers")),
            "{messages:#?}"
        );
    }

    #[test]
    fn writes_only_when_changed() {
        let dir = std::env::temp_dir().join(format!("mechgen-builder-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap_or_else(|e| panic!("{e}"));
        let path = dir.join("scene.rs");
        let scene = slider_crank();
        let options = CodegenOptions::default();
        scene
            .write_to(&path, &options)
            .unwrap_or_else(|e| panic!("{e}"));
        let written = std::fs::read_to_string(&path).unwrap_or_else(|e| panic!("{e}"));
        assert!(written.starts_with("// Generated by mechgen::builder"));
        let modified = std::fs::metadata(&path).and_then(|m| m.modified()).ok();
        scene
            .write_to(&path, &options)
            .unwrap_or_else(|e| panic!("{e}"));
        assert_eq!(
            std::fs::metadata(&path).and_then(|m| m.modified()).ok(),
            modified
        );
        let missing = dir.join("no/such/dir/scene.rs");
        let error = scene.write_to(&missing, &options).expect_err("an error");
        assert!(error.to_string().starts_with("cannot write"), "{error}");
        let _ = std::fs::remove_dir_all(&dir);
    }
}
