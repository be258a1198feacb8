//! Parsing: tokens (a `mechanism!` body or a `.mech` file) into a [`Spec`].
//!
//! The grammar (the reference below is `docs/grammar.md`, also on the `mechanism!` macro and
//! the runtime's front page). Only syntax is checked here; `check` does the rest.
//!
#![doc = include_str!("../../../docs/grammar.md")]

use proc_macro2::TokenStream;
use syn::parse::{Parse, ParseStream};
use syn::{Attribute, Ident, LitFloat, LitInt, Token, Visibility, braced, parenthesized};

use crate::syntax::spec::{
    BinOp, BodyDecl, BranchDecl, DriverDecl, DriverKind, DriverValue, Expr, ExprKind, GravityDecl,
    JointDecl, JointKind, LoadDecl, LoadKind, MarkerDecl, MarkerKind, MassDecl, ParamDecl,
    PointDecl, PointRef, Product, Sign, Spec,
};

mod kw {
    syn::custom_keyword!(mechanism);
    syn::custom_keyword!(param);
    syn::custom_keyword!(ground);
    syn::custom_keyword!(body);
    syn::custom_keyword!(joint);
    syn::custom_keyword!(driver);
    syn::custom_keyword!(free);
    syn::custom_keyword!(from);
    syn::custom_keyword!(speed);
    syn::custom_keyword!(at);
    syn::custom_keyword!(near);
    syn::custom_keyword!(along);
    syn::custom_keyword!(outputs);
    syn::custom_keyword!(branch);
    syn::custom_keyword!(mass);
    syn::custom_keyword!(inertia);
    syn::custom_keyword!(centre);
    syn::custom_keyword!(center);
    syn::custom_keyword!(gravity);
    syn::custom_keyword!(load);
    syn::custom_keyword!(marker);
    syn::custom_keyword!(point);
    syn::custom_keyword!(stiffness);
    syn::custom_keyword!(length);
    syn::custom_keyword!(damping);
}

/// Parses a `mechanism` declaration from tokens (the macro's input).
///
/// # Errors
/// Input beyond the size limits (`limits`), or the first syntax error, at its tokens.
pub fn parse_tokens(tokens: TokenStream) -> syn::Result<Spec> {
    crate::syntax::limits::check(&tokens)?;
    syn::parse2(tokens)
}

/// `/// docs pub mechanism Name`: everything before the body.
pub(crate) fn header(input: ParseStream) -> syn::Result<(Vec<Attribute>, Visibility, Ident)> {
    let docs = doc_attributes(input)?;
    let vis: Visibility = input.parse()?;
    input.parse::<kw::mechanism>().map_err(|e| {
        syn::Error::new(
            e.span(),
            "expected `mechanism Name { … }` (optionally preceded by doc comments and `pub`)",
        )
    })?;
    Ok((docs, vis, input.parse()?))
}

impl Spec {
    /// A spec with its header and no statements yet.
    pub(crate) fn new(docs: Vec<Attribute>, vis: Visibility, name: Ident) -> Self {
        Spec {
            docs,
            vis,
            name,
            params: Vec::new(),
            bodies: Vec::new(),
            joints: Vec::new(),
            drivers: Vec::new(),
            branches: Vec::new(),
            gravity: None,
            loads: Vec::new(),
            markers: Vec::new(),
            points: Vec::new(),
            outputs: None,
        }
    }
}

impl Parse for Spec {
    fn parse(input: ParseStream) -> syn::Result<Self> {
        let (docs, vis, name) = header(input)?;
        let content;
        braced!(content in input);
        let mut spec = Spec::new(docs, vis, name);
        while !content.is_empty() {
            statement(&content, &mut spec)?;
        }
        if !input.is_empty() {
            return Err(input.error("unexpected tokens after the mechanism's closing brace"));
        }
        Ok(spec)
    }
}

/// Outer attributes, of which only doc comments are accepted.
fn doc_attributes(input: ParseStream) -> syn::Result<Vec<Attribute>> {
    let attrs = Attribute::parse_outer(input)?;
    for attr in &attrs {
        if !attr.path().is_ident("doc") {
            return Err(syn::Error::new_spanned(
                attr,
                "only doc comments (`///`) are allowed here; remove this attribute",
            ));
        }
    }
    Ok(attrs)
}

/// One `;`-terminated statement of the body, added to `spec`.
pub(crate) fn statement(input: ParseStream, spec: &mut Spec) -> syn::Result<()> {
    // Whole: one arm per statement keyword of the grammar, each a few lines.
    let docs = doc_attributes(input)?;
    let look = input.lookahead1();
    if look.peek(kw::param) {
        input.parse::<kw::param>()?;
        let name = input.parse()?;
        input.parse::<Token![=]>()?;
        let default = input.parse()?;
        spec.params.push(ParamDecl {
            docs,
            name,
            default,
        });
    } else if look.peek(kw::ground) || look.peek(kw::body) {
        spec.bodies.push(body(input, docs)?);
    } else if look.peek(kw::joint) {
        input.parse::<kw::joint>()?;
        let name = input.parse()?;
        input.parse::<Token![:]>()?;
        let (kind_span, kind) = joint_kind(input)?;
        spec.joints.push(JointDecl {
            docs,
            name,
            kind_span,
            kind,
        });
    } else if look.peek(kw::outputs) {
        let keyword = input.parse::<kw::outputs>()?;
        if !docs.is_empty() || spec.outputs.is_some() {
            return Err(syn::Error::new(
                keyword.span,
                "a scene has at most one `outputs` statement, without doc comments",
            ));
        }
        let names =
            syn::punctuated::Punctuated::<Ident, Token![,]>::parse_separated_nonempty(input)?;
        spec.outputs = Some(names.into_iter().collect());
    } else if look.peek(kw::driver) {
        input.parse::<kw::driver>()?;
        let name = input.parse()?;
        input.parse::<Token![:]>()?;
        let (kind_span, kind) = driver_kind(input)?;
        input.parse::<Token![=]>()?;
        let value = DriverValue::Prescribed(input.parse()?);
        spec.drivers.push(DriverDecl {
            docs,
            name,
            kind_span,
            kind,
            value,
        });
    } else if look.peek(kw::free) {
        let keyword = input.parse::<kw::free>()?.span;
        let name = input.parse()?;
        input.parse::<Token![:]>()?;
        let (kind_span, kind) = driver_kind(input)?;
        let value = free_value(input, keyword)?;
        spec.drivers.push(DriverDecl {
            docs,
            name,
            kind_span,
            kind,
            value,
        });
    } else if look.peek(kw::branch) {
        input.parse::<kw::branch>()?;
        let name = input.parse()?;
        input.parse::<Token![:]>()?;
        spec.branches.push(branch(input, docs, name)?);
    } else if look.peek(kw::gravity) {
        let keyword = input.parse::<kw::gravity>()?;
        if !docs.is_empty() || spec.gravity.is_some() {
            return Err(syn::Error::new(
                keyword.span,
                "a scene has at most one `gravity (gx, gy);` statement, without doc comments",
            ));
        }
        let (value, _) = tuple::<2>(input, "(gx, gy): gravity's world components")?;
        spec.gravity = Some(GravityDecl {
            span: keyword.span,
            value,
        });
    } else if look.peek(kw::marker) {
        input.parse::<kw::marker>()?;
        let name = input.parse()?;
        input.parse::<Token![:]>()?;
        let kind = marker_kind(input)?;
        spec.markers.push(MarkerDecl { docs, name, kind });
    } else if look.peek(kw::point) {
        input.parse::<kw::point>()?;
        let name = input.parse()?;
        input.parse::<Token![:]>()?;
        let point = input.parse()?;
        spec.points.push(PointDecl { docs, name, point });
    } else if look.peek(kw::load) {
        input.parse::<kw::load>()?;
        let name = input.parse()?;
        input.parse::<Token![:]>()?;
        let (kind_span, kind) = load_kind(input)?;
        spec.loads.push(LoadDecl {
            docs,
            name,
            kind_span,
            kind,
        });
    } else {
        return Err(look.error());
    }
    input.parse::<Token![;]>()?;
    Ok(())
}

/// `ground NAME at (x, y, angle)` or `body NAME near (x, y, angle)`, then its mass clause.
fn body(input: ParseStream, docs: Vec<Attribute>) -> syn::Result<BodyDecl> {
    let ground = input.peek(kw::ground);
    let keyword = input.span();
    if ground {
        input.parse::<kw::ground>()?;
    } else {
        input.parse::<kw::body>()?;
    }
    let name = input.parse()?;
    if ground {
        input.parse::<kw::at>().map_err(|e| {
            syn::Error::new(
                e.span(),
                "expected `at (x, y, angle)`: the ground body's pose",
            )
        })?;
    } else {
        input.parse::<kw::near>().map_err(|e| {
            syn::Error::new(e.span(), "expected `near (x, y, angle)`: an initial guess")
        })?;
    }
    let (pose, _) = tuple::<3>(input, "(x, y, angle)")?;
    let mass = mass_clause(input)?;
    Ok(BodyDecl {
        docs,
        keyword,
        name,
        ground,
        pose,
        mass,
    })
}

/// A marker's kind (after `marker NAME:`): `angle(a, b)` or a point.
fn marker_kind(input: ParseStream) -> syn::Result<MarkerKind> {
    // `angle(a, b)` is a sensor; anything else a point (a body named `angle` still works
    // as `angle @ (x, y)` or `angle` alone).
    if input.peek(Ident) && input.peek2(syn::token::Paren) {
        let kind: Ident = input.parse()?;
        if kind != "angle" {
            return Err(syn::Error::new(
                kind.span(),
                format!(
                    "unknown marker `{kind}(…)`; a marker tracks a point, `marker NAME: \
                     body @ (x, y);`, or an angle between two bodies, `marker NAME: \
                     angle(a, b);`"
                ),
            ));
        }
        let args;
        parenthesized!(args in input);
        let a = args.parse()?;
        args.parse::<Token![,]>()?;
        let b = args.parse()?;
        if !args.is_empty() {
            return Err(args.error("unexpected argument: `angle` takes two bodies: `angle(a, b)`"));
        }
        Ok(MarkerKind::Angle(a, b))
    } else {
        Ok(MarkerKind::Point(input.parse()?))
    }
}

/// `cross(p1 -> p2, p3 -> p4) > 0` (after `branch NAME:`); the right-hand side is parsed as an
/// expression and held to the literal 0 by `check`, so that mistake is reported with the others.
fn branch(input: ParseStream, docs: Vec<Attribute>, name: Ident) -> syn::Result<BranchDecl> {
    let kind: Ident = input.parse()?;
    let product = match kind.to_string().as_str() {
        "cross" => Product::Cross,
        "dot" => Product::Dot,
        other => {
            return Err(syn::Error::new(
                kind.span(),
                format!(
                    "unknown branch invariant `{other}`; expected `cross(p1 -> p2, p3 -> p4)` \
                     or `dot(p1 -> p2, p3 -> p4)`"
                ),
            ));
        }
    };
    let args;
    parenthesized!(args in input);
    let u = vector(&args)?;
    args.parse::<Token![,]>()?;
    let v = vector(&args)?;
    if !args.is_empty() {
        return Err(args.error(
            "unexpected argument; a branch invariant takes two vectors: `p1 -> p2, p3 -> p4`",
        ));
    }
    let strict = "compare a branch invariant strictly with zero: `> 0` or `< 0`";
    if input.peek(Token![>=])
        || input.peek(Token![<=])
        || input.peek(Token![==])
        || input.peek(Token![!=])
    {
        return Err(input.error(strict));
    }
    let sign = if input.peek(Token![>]) {
        input.parse::<Token![>]>()?;
        Sign::Positive
    } else if input.peek(Token![<]) {
        input.parse::<Token![<]>()?;
        Sign::Negative
    } else {
        return Err(input.error(strict));
    };
    let zero = input.parse()?;
    Ok(BranchDecl {
        docs,
        name,
        product,
        product_span: kind.span(),
        u,
        v,
        sign,
        zero,
    })
}

/// `p1 -> p2`: the world vector from one point to another.
fn vector(input: ParseStream) -> syn::Result<[PointRef; 2]> {
    let from = input.parse()?;
    input.parse::<Token![->]>().map_err(|e| {
        syn::Error::new(
            e.span(),
            "expected `->`: a vector is written `from -> to`, such as `rod @ (0, 10) -> crank`",
        )
    })?;
    let to = input.parse()?;
    Ok([from, to])
}

/// The joint kinds and how each is written, for error messages.
const JOINT_KINDS: &str = "`revolute(a @ (x, y), b @ (x, y))`, `prismatic(a, b, along (ux, uy))`, \
     `distance(a, b, length)`, `slot(a @ (x, y), b @ (x, y), along (ux, uy))`, \
     `weld(a @ (x, y), b @ (x, y))`, `gear(a, b, ratio k[, carrier c])` or \
     `rack(prismatic_joint, pinion, ratio r)`";

/// A joint's kind and arguments (after `joint NAME:`).
fn joint_kind(input: ParseStream) -> syn::Result<(proc_macro2::Span, JointKind)> {
    // Whole: one arm per joint kind of the grammar.
    let kind: Ident = input.parse()?;
    let args;
    parenthesized!(args in input);
    let a: PointRef = args.parse()?;
    args.parse::<Token![,]>()?;
    let b: PointRef = args.parse()?;
    let name = kind.to_string();
    let usage = joint_usage(&kind)?;
    let joint = match name.as_str() {
        "revolute" => JointKind::Revolute { a, b },
        "prismatic" | "slot" => {
            args.parse::<Token![,]>()?;
            let (axis, axis_span) = along(&args)?;
            if name == "slot" {
                JointKind::Slot {
                    a,
                    b,
                    axis,
                    axis_span,
                }
            } else {
                JointKind::Prismatic {
                    a,
                    b,
                    axis,
                    axis_span,
                }
            }
        }
        "distance" => {
            args.parse::<Token![,]>()?;
            let length = args.parse()?;
            JointKind::Distance { a, b, length }
        }
        "weld" => {
            let mut options = Keywords::parse(&args, &["angle"], usage)?;
            JointKind::Weld {
                a,
                b,
                angle: options.take("angle"),
            }
        }
        "gear" => {
            let (a, b) = (whole_body(a, usage)?, whole_body(b, usage)?);
            let mut options = Keywords::parse(&args, &["ratio", "carrier", "phase"], usage)?;
            let ratio = options.required("ratio", kind.span(), usage)?;
            let carrier = match options.take("carrier") {
                Some(Expr {
                    kind: ExprKind::Name(body),
                    ..
                }) => Some(body),
                Some(other) => return Err(syn::Error::new(other.span, usage)),
                None => None,
            };
            JointKind::Gear {
                a,
                b,
                ratio,
                carrier,
                phase: options.take("phase"),
            }
        }
        _ => {
            let (joint, pinion) = (whole_body(a, usage)?, whole_body(b, usage)?);
            let mut options = Keywords::parse(&args, &["ratio", "phase"], usage)?;
            JointKind::Rack {
                joint,
                pinion,
                ratio: options.required("ratio", kind.span(), usage)?,
                phase: options.take("phase"),
            }
        }
    };
    if !args.is_empty() {
        return Err(args.error(format!("unexpected argument: {usage}")));
    }
    Ok((kind.span(), joint))
}

/// How a joint of kind `kind` is written, for its error messages; an error for an unknown
/// kind.
fn joint_usage(kind: &Ident) -> syn::Result<&'static str> {
    let usage = match kind.to_string().as_str() {
        "revolute" => "`revolute` joins two points: `revolute(a @ (x, y), b @ (x, y))`",
        "prismatic" => {
            "`prismatic` takes two bodies and an axis: `prismatic(a, b, along (ux, uy))`"
        }
        "distance" => "`distance` takes two points and a length: `distance(a @ (x, y), b, length)`",
        "slot" => {
            "`slot` takes a point on the slot, the pin and the slot's direction: \
             `slot(a @ (x, y), b @ (x, y), along (ux, uy))`"
        }
        "weld" => {
            "`weld` takes two points and optionally their relative angle: \
             `weld(a @ (x, y), b @ (x, y), angle 30deg)`"
        }
        "gear" => {
            "`gear` takes two bodies and their ratio, optionally a carrier and a phase: \
             `gear(sun, planet, ratio -2, carrier arm, phase 0.1)`"
        }
        "rack" => {
            "`rack` takes a prismatic joint, the pinion and the travel per radian: \
             `rack(slide, pinion, ratio 20, phase 0)`"
        }
        other => {
            return Err(syn::Error::new(
                kind.span(),
                format!("unknown joint kind `{other}`; expected {JOINT_KINDS}"),
            ));
        }
    };
    Ok(usage)
}

/// `along (ux, uy)`: an axis in the first body's frame.
fn along(input: ParseStream) -> syn::Result<([Expr; 2], proc_macro2::Span)> {
    input.parse::<kw::along>().map_err(|e| {
        syn::Error::new(
            e.span(),
            "expected `along (ux, uy)`: the axis in the first body's frame",
        )
    })?;
    tuple::<2>(input, "(ux, uy)")
}

/// A body named alone (`gear(sun, planet, …)`), not a point of it.
fn whole_body(point: PointRef, usage: &str) -> syn::Result<Ident> {
    match point.local {
        None => Ok(point.body),
        Some(_) => Err(syn::Error::new(
            point.body.span(),
            format!("name the body alone, without `@ (x, y)`: {usage}"),
        )),
    }
}

/// Keyword arguments after a joint's points, `, ratio -2, carrier arm`, each at most once, in
/// any order.
struct Keywords(Vec<(Ident, Expr)>);

impl Keywords {
    fn parse(input: ParseStream, allowed: &[&str], usage: &str) -> syn::Result<Self> {
        let mut found: Vec<(Ident, Expr)> = Vec::new();
        while !input.is_empty() {
            input.parse::<Token![,]>()?;
            let keyword: Ident = input.parse()?;
            if !allowed.iter().any(|a| keyword == a) {
                return Err(syn::Error::new(
                    keyword.span(),
                    format!("unexpected `{keyword}`: {usage}"),
                ));
            }
            if found.iter().any(|(k, _)| *k == keyword) {
                return Err(syn::Error::new(
                    keyword.span(),
                    format!("`{keyword}` is given twice; keep one"),
                ));
            }
            found.push((keyword, input.parse()?));
        }
        Ok(Keywords(found))
    }

    fn take(&mut self, keyword: &str) -> Option<Expr> {
        let k = self.0.iter().position(|(k, _)| k == keyword)?;
        Some(self.0.remove(k).1)
    }

    fn required(
        &mut self,
        keyword: &str,
        span: proc_macro2::Span,
        usage: &str,
    ) -> syn::Result<Expr> {
        self.take(keyword)
            .ok_or_else(|| syn::Error::new(span, format!("missing `{keyword}`: {usage}")))
    }
}

fn driver_kind(input: ParseStream) -> syn::Result<(proc_macro2::Span, DriverKind)> {
    let kind: Ident = input.parse()?;
    let args;
    parenthesized!(args in input);
    let driver = match kind.to_string().as_str() {
        "angle" => DriverKind::Angle(args.parse()?),
        "relative_angle" => {
            let a = args.parse()?;
            args.parse::<Token![,]>()?;
            DriverKind::RelativeAngle(a, args.parse()?)
        }
        "x" => DriverKind::X(args.parse()?),
        "y" => DriverKind::Y(args.parse()?),
        "travel" => DriverKind::Travel(args.parse()?),
        "distance" => {
            let a = args.parse()?;
            args.parse::<Token![,]>()?;
            DriverKind::Distance(a, args.parse()?)
        }
        "slide" => {
            let a = args.parse()?;
            args.parse::<Token![,]>()?;
            let b = args.parse()?;
            args.parse::<Token![,]>()?;
            let (axis, axis_span) = along(&args)?;
            DriverKind::Slide {
                a,
                b,
                axis,
                axis_span,
            }
        }
        other => {
            return Err(syn::Error::new(
                kind.span(),
                format!(
                    "unknown driver kind `{other}`; expected `angle(body)`, \
                     `relative_angle(a, b)`, `x(body @ (x, y))`, `y(body @ (x, y))`, \
                     `travel(prismatic_joint)`, `distance(a @ (x, y), b @ (x, y))` or \
                     `slide(a @ (x, y), b @ (x, y), along (ux, uy))`"
                ),
            ));
        }
    };
    if !args.is_empty() {
        let advice = driver_usage(&driver);
        return Err(args.error(format!("unexpected argument: {advice}")));
    }
    Ok((kind.span(), driver))
}

/// `[from u0] [speed v0]` after a free degree of freedom's kind, in this order.
fn free_value(input: ParseStream, keyword: proc_macro2::Span) -> syn::Result<DriverValue> {
    let from = if input.peek(kw::from) {
        input.parse::<kw::from>()?;
        Some(input.parse()?)
    } else {
        None
    };
    let speed = if input.peek(kw::speed) {
        input.parse::<kw::speed>()?;
        Some(input.parse()?)
    } else {
        None
    };
    if input.peek(Token![=]) {
        return Err(input.error(
            "a free degree of freedom has no prescribed value: the forces move it; write \
             `free NAME: KIND(…) from u0 speed v0;` for its initial state, or `driver NAME: \
             KIND(…) = f(t);` to prescribe it",
        ));
    }
    Ok(DriverValue::Free {
        keyword,
        from,
        speed,
    })
}

/// How a driver of `driver`'s kind is written, for an error about its arguments.
fn driver_usage(driver: &DriverKind) -> &'static str {
    match driver {
        DriverKind::Angle(_) => {
            "`angle` drives one body's absolute angle; to drive the angle between two \
             bodies, write `relative_angle(a, b)`"
        }
        DriverKind::X(_) | DriverKind::Y(_) => {
            "`x` and `y` drive one point's global coordinate: `x(body @ (px, py))`"
        }
        DriverKind::Travel(_) => "`travel` takes the name of one prismatic joint: `travel(slide)`",
        DriverKind::RelativeAngle(..) => {
            "`relative_angle` takes two bodies: `relative_angle(a, b)`"
        }
        DriverKind::Distance(..) => {
            "`distance` takes two points: `distance(a @ (x, y), b @ (x, y))`"
        }
        DriverKind::Slide { .. } => {
            "`slide` takes two points and an axis: `slide(a @ (x, y), b, along (ux, uy))`"
        }
    }
}

/// `mass m`, `inertia J` and `centre (x, y)` after a body's pose, in any order, each at most
/// once; `None` when there is none.
fn mass_clause(input: ParseStream) -> syn::Result<Option<MassDecl>> {
    let start = input.span();
    let (mut mass, mut inertia, mut centre) = (None, None, None);
    loop {
        let span = input.span();
        let (taken, what) = if input.peek(kw::mass) {
            input.parse::<kw::mass>()?;
            (Option::replace(&mut mass, input.parse()?).is_some(), "mass")
        } else if input.peek(kw::inertia) {
            input.parse::<kw::inertia>()?;
            (
                Option::replace(&mut inertia, input.parse()?).is_some(),
                "inertia",
            )
        } else if input.peek(kw::centre) || input.peek(kw::center) {
            let _: Ident = input.parse()?;
            let (xy, _) = tuple::<2>(input, "(x, y): the centre of mass in the body's frame")?;
            (centre.replace((xy, span)).is_some(), "centre")
        } else {
            break;
        };
        if taken {
            return Err(syn::Error::new(
                span,
                format!("`{what}` is given twice for this body; keep one"),
            ));
        }
    }
    let declared = mass.is_some() || inertia.is_some() || centre.is_some();
    Ok(declared.then_some(MassDecl {
        span: start,
        mass,
        inertia,
        centre,
    }))
}

/// `force(p) = (fx, fy)`, `local_force(p) = (fx, fy)`, `torque(body) = τ` or
/// `spring(p, q, stiffness k, length L, damping c)` (after `load NAME:`).
fn load_kind(input: ParseStream) -> syn::Result<(proc_macro2::Span, LoadKind)> {
    let kind: Ident = input.parse()?;
    let args;
    parenthesized!(args in input);
    let surplus = |args: ParseStream, advice: &str| -> syn::Result<()> {
        if args.is_empty() {
            Ok(())
        } else {
            Err(args.error(format!("unexpected argument: {advice}")))
        }
    };
    let load = match kind.to_string().as_str() {
        "force" | "local_force" => {
            let point = args.parse()?;
            surplus(
                &args,
                "a force acts at one point: `force(body @ (x, y)) = (fx, fy)`",
            )?;
            input.parse::<Token![=]>()?;
            let (value, _) = tuple::<2>(input, "(fx, fy): the force's components")?;
            LoadKind::Force {
                point,
                value,
                local: kind == "local_force",
            }
        }
        "torque" => {
            let body = args.parse()?;
            surplus(&args, "a torque turns one body: `torque(body) = value`")?;
            input.parse::<Token![=]>()?;
            LoadKind::Torque {
                body,
                value: input.parse()?,
            }
        }
        "spring" => spring(&args)?,
        other => {
            return Err(syn::Error::new(
                kind.span(),
                format!(
                    "unknown load kind `{other}`; expected `force(body @ (x, y)) = (fx, fy)`, \
                     `local_force(body @ (x, y)) = (fx, fy)`, `torque(body) = value` or \
                     `spring(a @ (x, y), b, stiffness k, length L, damping c)`"
                ),
            ));
        }
    };
    Ok((kind.span(), load))
}

/// `spring(p, q, stiffness k, length L, damping c)`'s arguments, the keywords in any order,
/// each at most once.
fn spring(args: ParseStream) -> syn::Result<LoadKind> {
    let a = args.parse()?;
    args.parse::<Token![,]>()?;
    let b = args.parse()?;
    let (mut stiffness, mut length, mut damping) = (None, None, None);
    while !args.is_empty() {
        args.parse::<Token![,]>()?;
        let span = args.span();
        let slot = if args.peek(kw::stiffness) {
            args.parse::<kw::stiffness>()?;
            &mut stiffness
        } else if args.peek(kw::length) {
            args.parse::<kw::length>()?;
            &mut length
        } else if args.peek(kw::damping) {
            args.parse::<kw::damping>()?;
            &mut damping
        } else {
            return Err(args.error(
                "expected `stiffness k`, `length L` or `damping c`, as in \
                 `spring(a @ (x, y), b, stiffness 20, length 35, damping 0.1)`",
            ));
        };
        if slot.replace(args.parse()?).is_some() {
            return Err(syn::Error::new(
                span,
                "this spring argument is given twice; keep one",
            ));
        }
    }
    Ok(LoadKind::Spring {
        a,
        b,
        stiffness,
        length,
        damping,
    })
}

impl Parse for PointRef {
    fn parse(input: ParseStream) -> syn::Result<Self> {
        let body = input.parse()?;
        let local = if input.peek(Token![@]) {
            input.parse::<Token![@]>()?;
            Some(tuple::<2>(input, "(x, y)")?.0)
        } else {
            None
        };
        Ok(PointRef { body, local })
    }
}

/// `(e1, …, eN)` with exactly N expressions (`what` names them for the error), and its span.
fn tuple<const N: usize>(
    input: ParseStream,
    what: &str,
) -> syn::Result<([Expr; N], proc_macro2::Span)> {
    if !input.peek(syn::token::Paren) {
        return Err(input.error(format!(
            "expected {N} comma-separated values in parentheses: {what}"
        )));
    }
    let content;
    let paren = parenthesized!(content in input);
    let mut items = Vec::with_capacity(N);
    while !content.is_empty() {
        items.push(content.parse::<Expr>()?);
        if content.is_empty() {
            break;
        }
        content.parse::<Token![,]>()?;
    }
    let found = items.len();
    let span = paren.span.join();
    let items = items.try_into().map_err(|_| {
        syn::Error::new(
            span,
            format!("expected {N} comma-separated values {what}, found {found}"),
        )
    })?;
    Ok((items, span))
}

impl Parse for Expr {
    fn parse(input: ParseStream) -> syn::Result<Self> {
        binary(input, 0)
    }
}

/// Precedence climbing over `+ -` (1) and `* /` (2), left-associative.
fn binary(input: ParseStream, min_prec: u8) -> syn::Result<Expr> {
    let mut lhs = unary(input)?;
    loop {
        let (op, prec) = if input.peek(Token![+]) {
            (BinOp::Add, 1)
        } else if input.peek(Token![-]) {
            (BinOp::Sub, 1)
        } else if input.peek(Token![*]) {
            (BinOp::Mul, 2)
        } else if input.peek(Token![/]) {
            (BinOp::Div, 2)
        } else {
            return Ok(lhs);
        };
        if prec < min_prec {
            return Ok(lhs);
        }
        let span = input.span();
        input.parse::<proc_macro2::Punct>()?;
        let rhs = binary(input, prec + 1)?;
        lhs = Expr {
            span,
            kind: ExprKind::Binary(op, Box::new(lhs), Box::new(rhs)),
        };
    }
}

/// Unary minus binds looser than `^`: `-x^2` is `-(x^2)`.
fn unary(input: ParseStream) -> syn::Result<Expr> {
    if input.peek(Token![-]) {
        let span = input.span();
        input.parse::<Token![-]>()?;
        let operand = unary(input)?;
        return Ok(Expr {
            span,
            kind: ExprKind::Neg(Box::new(operand)),
        });
    }
    power(input)
}

/// The largest integer exponent: differentiating `x^n` twice (for γ) lowers it by two, which
/// must stay an `i32`. (Any exponent near this overflows or vanishes for every base but 1.)
const MAX_INTEGER_POWER: i32 = 1 << 30;

fn power(input: ParseStream) -> syn::Result<Expr> {
    let base = atom(input)?;
    if !input.peek(Token![^]) {
        return Ok(base);
    }
    let span = input.span();
    input.parse::<Token![^]>()?;
    // An integer literal (optionally negative) is an integer power, exact for any base;
    // anything else is a real power.
    let fork = input.fork();
    let negative = fork.parse::<Option<Token![-]>>()?.is_some();
    if fork.peek(LitInt) && !fork.peek2(Token![.]) {
        input.parse::<Option<Token![-]>>()?;
        let exponent: LitInt = input.parse()?;
        if !exponent.suffix().is_empty() {
            return Err(syn::Error::new(
                exponent.span(),
                "an exponent takes no suffix: write `x^2`",
            ));
        }
        let magnitude = exponent
            .base10_parse::<u64>()
            .ok()
            .and_then(|m| i32::try_from(m).ok())
            .filter(|&m| m <= MAX_INTEGER_POWER)
            .ok_or_else(|| {
                syn::Error::new(
                    exponent.span(),
                    format!(
                        "the integer exponent `{}` is too large: an integer power takes at most \
                         {MAX_INTEGER_POWER} in magnitude; for a real power (of a positive \
                         base) write the exponent as a decimal number, `x^{}.0`",
                        exponent.base10_digits(),
                        exponent.base10_digits(),
                    ),
                )
            })?;
        let n = if negative { -magnitude } else { magnitude };
        return Ok(Expr {
            span,
            kind: ExprKind::Pow(Box::new(base), n),
        });
    }
    let exponent = unary(input).map_err(|e| {
        syn::Error::new(
            e.span(),
            "`^` takes an exponent: an integer (`t^2`, `x^-1`), a number (`x^1.5`), a \
             parameter or a parenthesised expression",
        )
    })?;
    Ok(Expr {
        span,
        kind: ExprKind::RealPow(Box::new(base), Box::new(exponent)),
    })
}

fn atom(input: ParseStream) -> syn::Result<Expr> {
    let span = input.span();
    if input.peek(syn::token::Paren) {
        let content;
        let paren = parenthesized!(content in input);
        let first: Expr = content.parse()?;
        if content.is_empty() {
            return Ok(first);
        }
        if !content.peek(Token![,]) {
            return Err(content.error("expected `)` after the expression"));
        }
        // `(a, b, …)`: a spline point.
        let mut items = vec![first];
        while !content.is_empty() {
            content.parse::<Token![,]>()?;
            if content.is_empty() {
                break;
            }
            items.push(content.parse()?);
        }
        return Ok(Expr {
            span: paren.span.join(),
            kind: ExprKind::Tuple(items),
        });
    }
    if input.peek(LitFloat) {
        let lit: LitFloat = input.parse()?;
        return number(lit.base10_digits(), lit.suffix(), span);
    }
    if input.peek(LitInt) {
        let lit: LitInt = input.parse()?;
        return number(lit.base10_digits(), lit.suffix(), span);
    }
    if input.peek(Ident) {
        let name: Ident = input.parse()?;
        if input.peek(syn::token::Paren) {
            let content;
            parenthesized!(content in input);
            let args = syn::punctuated::Punctuated::<Expr, Token![,]>::parse_terminated(&content)?;
            return Ok(Expr {
                span,
                kind: ExprKind::Call(name, args.into_iter().collect()),
            });
        }
        return Ok(Expr {
            span,
            kind: ExprKind::Name(name),
        });
    }
    Err(input.error("expected a number, `t`, a parameter, a function call or `(`"))
}

/// A numeric literal; the suffix `deg` turns degrees into radians (`30deg`).
fn number(digits: &str, suffix: &str, span: proc_macro2::Span) -> syn::Result<Expr> {
    let scale = match suffix {
        "" => 1.0,
        "deg" => core::f64::consts::PI / 180.0,
        _ => {
            return Err(syn::Error::new(
                span,
                format!(
                    "remove the `{suffix}` suffix: every number is an f64 (only `deg`, for \
                     degrees, is accepted: `30deg`)"
                ),
            ));
        }
    };
    let value: f64 = digits
        .parse()
        .map_err(|_| syn::Error::new(span, "not a valid number"))?;
    let value = value * scale;
    if !value.is_finite() {
        return Err(syn::Error::new(span, "number is too large for an f64"));
    }
    Ok(Expr {
        span,
        kind: ExprKind::Number(value),
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::syntax::source::parse_str;

    fn show(e: &Expr) -> String {
        match &e.kind {
            ExprKind::Number(v) => format!("{v}"),
            ExprKind::Name(n) => n.to_string(),
            ExprKind::Neg(a) => format!("(-{})", show(a)),
            ExprKind::Binary(op, a, b) => {
                let op = match op {
                    BinOp::Add => "+",
                    BinOp::Sub => "-",
                    BinOp::Mul => "*",
                    BinOp::Div => "/",
                };
                format!("({} {op} {})", show(a), show(b))
            }
            ExprKind::Pow(a, n) => format!("({}^{n})", show(a)),
            ExprKind::RealPow(a, b) => format!("({}^{})", show(a), show(b)),
            ExprKind::Call(f, args) => {
                let args: Vec<String> = args.iter().map(show).collect();
                format!("{f}({})", args.join(", "))
            }
            ExprKind::Tuple(items) => {
                let items: Vec<String> = items.iter().map(show).collect();
                format!("({})", items.join(", "))
            }
        }
    }

    fn expr(s: &str) -> String {
        show(&syn::parse_str::<Expr>(s).unwrap_or_else(|e| panic!("parses: {e}")))
    }

    #[test]
    fn precedence_and_associativity() {
        assert_eq!(expr("1 + 2 * t"), "(1 + (2 * t))");
        assert_eq!(expr("a - b - c"), "((a - b) - c)");
        assert_eq!(expr("a / b * c"), "((a / b) * c)");
        assert_eq!(expr("-t^2"), "(-(t^2))");
        assert_eq!(expr("(1 + t) * 2"), "((1 + t) * 2)");
        assert_eq!(expr("0.5 * sin(2000 * t)"), "(0.5 * sin((2000 * t)))");
        assert_eq!(expr("x^-1"), "(x^-1)");
        assert_eq!(expr("1e-6"), "0.000001");
        assert_eq!(expr("x^1.5"), "(x^1.5)");
        assert_eq!(expr("x^p * 2"), "((x^p) * 2)");
        assert_eq!(expr("x^-(a + b)"), "(x^(-(a + b)))");
        assert_eq!(expr("atan2(y, x) + 1"), "(atan2(y, x) + 1)");
        assert_eq!(
            expr("spline(t, (0, 1), (2, 3))"),
            "spline(t, (0, 1), (2, 3))"
        );
        assert_eq!(expr("180deg"), format!("{}", core::f64::consts::PI));
    }

    #[test]
    fn integer_exponents_stay_differentiable() {
        assert_eq!(expr("t^1073741824"), "(t^1073741824)");
        assert_eq!(expr("t^-1073741824"), "(t^-1073741824)");
        for huge in ["2147483648", "1073741825", "99999999999999999999999"] {
            let Err(error) = syn::parse_str::<Expr>(&format!("t^{huge}")) else {
                panic!("t^{huge} parsed");
            };
            let message = error.to_string();
            assert!(
                message.contains(&format!("the integer exponent `{huge}` is too large"))
                    && message.contains(&format!("`x^{huge}.0`")),
                "{message}"
            );
        }
        // The way out it suggests is a real power.
        assert_eq!(expr("t^2147483648.0"), "(t^2147483648)");
    }

    #[test]
    fn parses_the_seed() {
        let spec = parse_str(
            "/// Seed.\npub mechanism PistonCrank {
                param omega = 314;
                ground liner at (156.8, 0, 0);
                body piston near (130, 0, 0);
                body crank near (0, 0, 0);
                joint pin: revolute(piston @ (-28, 0), crank @ (0, 43));
                joint slide: prismatic(liner, piston, along (1, 0));
                joint link: distance(liner, crank, 10);
                driver spin: angle(crank) = omega * t;
            }",
        )
        .unwrap_or_else(|e| panic!("parses: {e}"));
        assert_eq!(spec.name, "PistonCrank");
        assert_eq!(spec.docs.len(), 1);
        assert_eq!(spec.params.len(), 1);
        assert_eq!(spec.bodies.len(), 3);
        assert!(spec.bodies[0].ground && !spec.bodies[1].ground);
        assert_eq!(spec.joints.len(), 3);
        assert_eq!(spec.drivers.len(), 1);
        assert!(matches!(spec.joints[1].kind, JointKind::Prismatic { .. }));
    }

    #[test]
    fn syntax_errors_say_what_was_expected() {
        let err = |s: &str| parse_str(s).err().expect("an error").to_string();
        assert!(
            err("mechanism M { joint j: hinge(a, b); }").contains("unknown joint kind `hinge`")
        );
        assert!(err("mechanism M { body b at (0, 0, 0); }").contains("near (x, y, angle)"));
        assert!(err("mechanism M { body b near (0, 0); }").contains("expected 3"));
        assert!(err("mechanism M { param p = 1f32; }").contains("suffix"));
        assert!(err("mechanism M { param p = t^; }").contains("takes an exponent"));
        assert!(err("mechanism M { param p = 3kg; }").contains("`deg`"));
        assert!(err("#[derive(Debug)] mechanism M {}").contains("only doc comments"));
        assert!(err("struct M {}").contains("mechanism Name"));
        assert!(err("mechanism M { branch b: cross(a -> b, c -> d) >= 0; }").contains("strictly"));
        assert!(err("mechanism M { branch b: cross(a -> b, c -> d); }").contains("`> 0` or `< 0`"));
        assert!(err("mechanism M { branch b: wedge(a -> b, c -> d) > 0; }").contains("`wedge`"));
        assert!(err("mechanism M { branch b: dot(a, b, c -> d) > 0; }").contains("`->`"));
        assert!(err("mechanism M { body b near (0, 0, 0) mass 1 mass 2; }").contains("twice"));
        assert!(err("mechanism M { gravity (0, 1); gravity (0, 2); }").contains("at most one"));
        assert!(err("mechanism M { load l: push(b) = (1, 0); }").contains("unknown load kind"));
        assert!(err("mechanism M { load l: spring(a, b, stiff 1); }").contains("`stiffness k`"));
        assert!(err("mechanism M { load l: torque(a, b) = 1; }").contains("turns one body"));
        assert!(err("mechanism M { load l: force(a) = 1; }").contains("expected 2"));
        assert!(err("mechanism M { body b near 1; }").contains("(x, y, angle)"));
    }

    #[test]
    fn parses_mass_properties_gravity_and_loads() {
        let spec = parse_str(
            "mechanism M {
                body rod near (0, 0, 0) centre (1, 2) mass m inertia 0.5;
                body arm near (0, 0, 0);
                gravity (0, -9.81);
                /// The gas force.
                load gas: force(rod @ (1, 0)) = (-p * t, 0);
                load thrust: local_force(arm) = (0, 1);
                load brake: torque(arm) = -t;
                load coil: spring(rod, arm @ (0, 1), damping 0.1, stiffness k, length 2);
            }",
        )
        .unwrap_or_else(|e| panic!("parses: {e}"));
        let mass = spec.bodies[0].mass.as_ref().expect("a mass clause");
        assert!(mass.mass.is_some() && mass.inertia.is_some() && mass.centre.is_some());
        assert!(spec.bodies[1].mass.is_none());
        assert!(spec.gravity.is_some());
        assert_eq!(spec.loads.len(), 4);
        assert_eq!(spec.loads[0].docs.len(), 1);
        assert!(matches!(
            spec.loads[1].kind,
            LoadKind::Force { local: true, .. }
        ));
        let LoadKind::Spring {
            stiffness,
            length,
            damping,
            ..
        } = &spec.loads[3].kind
        else {
            panic!("a spring");
        };
        assert!(stiffness.is_some() && length.is_some() && damping.is_some());
    }

    #[test]
    fn parses_branch_invariants() {
        let spec = parse_str(
            "mechanism M {
                /// Open assembly.
                branch open: cross(a @ (1, 0) -> b, b -> c @ (0, -2.5)) < 0;
                branch out: dot(a -> b, c -> d) > 0.0;
            }",
        )
        .unwrap_or_else(|e| panic!("parses: {e}"));
        assert_eq!(spec.branches.len(), 2);
        let open = &spec.branches[0];
        assert_eq!(open.name, "open");
        assert_eq!(open.docs.len(), 1);
        assert_eq!((open.product, open.sign), (Product::Cross, Sign::Negative));
        assert_eq!(open.u[0].body, "a");
        assert!(open.u[1].local.is_none());
        assert_eq!(open.v[1].body, "c");
        let out = &spec.branches[1];
        assert_eq!((out.product, out.sign), (Product::Dot, Sign::Positive));
        assert_eq!(show(&out.zero), "0");
    }
}
