//! The builder's arguments: a [`Value`] (a number or an expression) and a [`Point`] (a body
//! and a body-fixed offset), each convertible from what a caller has at hand.

/// A scalar of the spec: a number, or an expression in parameters (and `t` in drivers) written
/// in the grammar's syntax, e.g. `"omega * t"` or `"0.5 * sin(2 * t)"`.
#[derive(Debug, Clone, PartialEq)]
pub enum Value {
    /// A finite number, written with its shortest round-trip representation.
    Number(f64),
    /// An expression in the grammar's syntax; checked for syntax when added.
    Expr(String),
}

impl From<f64> for Value {
    fn from(value: f64) -> Self {
        Value::Number(value)
    }
}

impl From<&str> for Value {
    fn from(expr: &str) -> Self {
        Value::Expr(expr.to_owned())
    }
}

impl From<String> for Value {
    fn from(expr: String) -> Self {
        Value::Expr(expr)
    }
}

impl From<&String> for Value {
    fn from(expr: &String) -> Self {
        Value::Expr(expr.clone())
    }
}

/// A body-fixed point: a body's reference point (`"crank"`) or a point in its frame
/// (`("crank", [0.0, 43.0])`).
#[derive(Debug, Clone, PartialEq)]
pub struct Point {
    /// The body the point is fixed to.
    pub body: String,
    /// Body-frame coordinates; `None` for the reference point.
    pub local: Option<[f64; 2]>,
}

impl Point {
    /// The point at `local` in `body`'s frame.
    pub fn new(body: impl Into<String>, local: [f64; 2]) -> Self {
        Point {
            body: body.into(),
            local: Some(local),
        }
    }

    /// The reference point (origin) of `body`.
    pub fn origin(body: impl Into<String>) -> Self {
        Point {
            body: body.into(),
            local: None,
        }
    }
}

impl From<&str> for Point {
    fn from(body: &str) -> Self {
        Point::origin(body)
    }
}

impl From<String> for Point {
    fn from(body: String) -> Self {
        Point::origin(body)
    }
}

impl From<&String> for Point {
    fn from(body: &String) -> Self {
        Point::origin(body.as_str())
    }
}

impl From<(&str, [f64; 2])> for Point {
    fn from((body, local): (&str, [f64; 2])) -> Self {
        Point::new(body, local)
    }
}

impl From<(String, [f64; 2])> for Point {
    fn from((body, local): (String, [f64; 2])) -> Self {
        Point::new(body, local)
    }
}

impl From<(&String, [f64; 2])> for Point {
    fn from((body, local): (&String, [f64; 2])) -> Self {
        Point::new(body.as_str(), local)
    }
}
