//! Mobility: every moving body connected, the Gruebler count matched by the drivers, and a
//! structurally singular system ([`Structure`]) reported at the constraints to remove.

use syn::Ident;

use super::rank::Structure;
use super::{Checker, plural, redundancy};
use crate::model::Model;
use crate::syntax::spec::Spec;

impl Checker {
    /// Names every moving body that no joint joins and no driver moves: it floats freely, and
    /// the degree-of-freedom count would blame the drivers for it. Returns whether there is one.
    pub(super) fn check_floating(&mut self, spec: &Spec) -> bool {
        let joined = |body: &Ident| spec.joints.iter().any(|j| j.kind.bodies().contains(&body));
        let driven = |body: &Ident| spec.drivers.iter().any(|d| d.kind.bodies().contains(&body));
        let anchor = spec
            .bodies
            .iter()
            .find(|b| b.ground)
            .map_or_else(|| "OTHER".to_owned(), |b| b.name.to_string());
        let mut floating = false;
        for body in spec.bodies.iter().filter(|b| !b.ground) {
            if joined(&body.name) || driven(&body.name) {
                continue;
            }
            floating = true;
            self.errors.push(
                body.name.span(),
                format!(
                    "body `{0}` is not connected: no joint joins it and no driver moves it, so \
                     its three coordinates are free; connect it, e.g. `joint {0}_pin: \
                     revolute({0}, {anchor} @ (x, y));`, or remove it",
                    body.name
                ),
            );
        }
        floating
    }

    /// Gruebler count: each moving body has 3 coordinates, each joint removes its equations
    /// (ground bodies bring 3 coordinates and 3 equations, which cancel); drivers must take up
    /// exactly the rest so that the system is square. A square system must then also be
    /// structurally non-singular ([`Structure`]): no group of constraints may over-determine
    /// some bodies while others keep free coordinates.
    pub(super) fn check_mobility(
        &mut self,
        spec: &Spec,
        model: &Model,
        structure: &Structure,
        rows: &[Vec<usize>],
    ) {
        if self.check_floating(spec) {
            // A count would only blame the drivers for a body nothing holds.
            return;
        }
        let moving = spec.bodies.iter().filter(|b| !b.ground).count();
        let joint_equations: usize = spec.joints.iter().map(|j| j.kind.equations()).sum();
        let dof = 3 * moving as i64 - joint_equations as i64;
        let drivers = spec.drivers.len() as i64;
        let count = format!(
            "Gruebler count: 3 × {moving} moving bod{} − {joint_equations} joint equation{} = {}",
            if moving == 1 { "y" } else { "ies" },
            plural(joint_equations as i64),
            if dof < 0 {
                format!("−{}", -dof)
            } else {
                dof.to_string()
            },
        );
        let over = structure.over_constraints(model);
        let joints = removable_joints(spec, model, rows, structure, &over);
        if dof < 0 {
            self.over_constrained(spec, model, structure, &over, &joints, &count);
        } else if dof == 0 && drivers > 0 && !joints.is_empty() {
            // Drivers on a mechanism its joints hold rigid: a joint closed a loop twice.
            self.joint_takes_drivers_freedom(spec, &joints, dof, &count);
        } else if drivers < dof {
            self.too_few_drivers(spec, dof, &count);
        } else if drivers > dof {
            self.too_many_drivers(spec, dof, &count);
        } else if !structure.over_equations.is_empty() {
            self.structurally_redundant(spec, model, structure);
        }
    }

    /// More joint equations than coordinates: the error goes to the joint whose equations the
    /// others already impose, else to the last joint of the over-determined part.
    fn over_constrained(
        &mut self,
        spec: &Spec,
        model: &Model,
        structure: &Structure,
        over: &[usize],
        joints: &[&Ident],
        count: &str,
    ) {
        let ground = model.bodies.iter().filter(|b| b.ground).count();
        let part = if structure.over_equations.is_empty() {
            String::new()
        } else {
            format!(
                "; {} over-determine {} ({})",
                structure.statements(model),
                structure.over_bodies(model),
                structure.over_count(),
            )
        };
        // No joint whose equations are all redundant (without drivers, removing any
        // joint frees a coordinate): the error goes to the last joint of the part.
        let last = over
            .iter()
            .rev()
            .find_map(|&k| spec.joints.get(k.checked_sub(ground)?));
        let (span, fix) = match (joints.split_first(), last) {
            (Some((first, others)), _) => (
                first.span(),
                format!(
                    "{}: the other constraints already impose its equations",
                    remove_joint(first, others)
                ),
            ),
            (None, Some(last)) => (last.name.span(), "remove joints or add bodies".to_owned()),
            (None, None) => (spec.name.span(), "remove joints or add bodies".to_owned()),
        };
        self.errors.push(
            span,
            format!("the joints over-constrain the mechanism ({count}){part}; {fix}"),
        );
    }

    /// Fewer drivers than degrees of freedom: the error at the mechanism's name, with a driver
    /// to add under a free name.
    fn too_few_drivers(&mut self, spec: &Spec, dof: i64, count: &str) {
        let drivers = spec.drivers.len() as i64;
        let missing = dof - drivers;
        let example = spec
            .bodies
            .iter()
            .find(|b| !b.ground)
            .map_or_else(|| "BODY".to_owned(), |b| b.name.to_string());
        let taken = |name: &str| {
            let params = spec.params.iter().map(|p| &p.name);
            let joints = spec.joints.iter().map(|j| &j.name);
            let drivers = spec.drivers.iter().map(|d| &d.name);
            self.bodies.contains_key(name) || params.chain(joints).chain(drivers).any(|n| n == name)
        };
        let spin = (1..)
            .map(|k| {
                if k == 1 {
                    "spin".to_owned()
                } else {
                    format!("spin{k}")
                }
            })
            .find(|name| !taken(name))
            .unwrap_or_default();
        // A scene that moves under forces is told of `free`, one that is driven of `driver`.
        let message = if has_free(spec) {
            format!(
                "`{}` has {dof} degree{} of freedom but {drivers} drivers and free degrees of \
                 freedom ({count}); add {missing} more, e.g. `free {spin}: angle({example});`",
                spec.name,
                plural(dof),
            )
        } else {
            format!(
                "`{}` has {dof} degree{} of freedom but {drivers} driver{} ({count}); add \
                 {missing} driver{}, e.g. `driver {spin}: angle({example}) = t;`",
                spec.name,
                plural(dof),
                plural(drivers),
                plural(missing),
            )
        };
        self.errors.push(spec.name.span(), message);
    }

    /// More drivers than degrees of freedom: the error at each driver past the count.
    fn too_many_drivers(&mut self, spec: &Spec, dof: i64, count: &str) {
        let drivers = spec.drivers.len() as i64;
        let extra = drivers - dof;
        for driver in spec.drivers.iter().skip(dof as usize) {
            let message = if has_free(spec) {
                format!(
                    "too many drivers and free degrees of freedom: `{}` has {dof} degree{} of \
                     freedom but {drivers} ({count}); remove {extra}, such as `{}`",
                    spec.name,
                    plural(dof),
                    driver.name,
                )
            } else {
                format!(
                    "too many drivers: `{}` has {dof} degree{} of freedom but {drivers} \
                     driver{} ({count}); remove {extra} driver{}, such as `{}`",
                    spec.name,
                    plural(dof),
                    plural(drivers),
                    plural(extra),
                    driver.name,
                )
            };
            self.errors.push(driver.name.span(), message);
        }
    }

    /// A square system that is structurally singular: the error at every constraint of the
    /// over-determined part, naming the coordinates the under-determined part leaves free.
    fn structurally_redundant(&mut self, spec: &Spec, model: &Model, structure: &Structure) {
        let free: Vec<String> = structure
            .under_free
            .iter()
            .map(|&c| format!("`{}`", coordinate_name(model, c)))
            .collect();
        let under = structure.under_bodies(model);
        let message = format!(
            "structurally redundant constraints: {} over-determine {} ({}) while {} keep{} \
             {} coordinate{} free ({}), so the Jacobian is singular in every position \
             although the Gruebler count matches; remove one of these constraints and \
             constrain {} instead",
            structure.statements(model),
            structure.over_bodies(model),
            structure.over_count(),
            under,
            if structure.under_body_count(model) == 1 {
                "s"
            } else {
                ""
            },
            free.len(),
            plural(free.len() as i64),
            free.join(", "),
            under,
        );
        let ground = model.bodies.iter().filter(|b| b.ground).count();
        for &k in &structure.over_constraints(model) {
            let span = match k.checked_sub(ground) {
                Some(j) if j < spec.joints.len() => spec.joints[j].name.span(),
                Some(j) => spec
                    .drivers
                    .get(j - spec.joints.len())
                    .map_or(spec.name.span(), |d| d.name.span()),
                None => spec.name.span(),
            };
            self.errors.push(span, &message);
        }
    }

    /// Drivers on a mechanism its joints hold rigid, where some joint's equations are ones the
    /// other constraints already impose (a loop closed twice): the joint is named first, at its
    /// name, with the drivers as the other way out. (With freedom left, the drivers are what
    /// is too many.)
    pub(super) fn joint_takes_drivers_freedom(
        &mut self,
        spec: &Spec,
        joints: &[&Ident],
        dof: i64,
        count: &str,
    ) {
        let drivers = spec.drivers.len() as i64;
        let extra = drivers - dof;
        let (first, others) = joints.split_first().expect("a removable joint");
        let driver = spec
            .drivers
            .get(dof as usize)
            .map_or_else(String::new, |d| {
                format!(
                    ", or remove {extra} driver{}, such as `{}`",
                    plural(extra),
                    d.name
                )
            });
        self.errors.push(
            first.span(),
            format!(
                "too many constraints: `{}` has {dof} degree{} of freedom but {drivers} \
                 driver{} ({count}), and joint `{first}` over-constrains it: the other joints \
                 and the drivers already impose its equations; {}{driver}",
                spec.name,
                plural(dof),
                plural(drivers),
                remove_joint(first, others),
            ),
        );
    }
}

pub(super) fn coordinate_name(model: &Model, coordinate: usize) -> String {
    model
        .coordinate_names()
        .get(coordinate)
        .cloned()
        .unwrap_or_default()
}

/// "remove joint `a` (or `b`, `c`)".
pub(super) fn remove_joint(first: &Ident, others: &[&Ident]) -> String {
    let or = if others.is_empty() {
        String::new()
    } else {
        let names: Vec<String> = others.iter().map(|j| format!("`{j}`")).collect();
        format!(" (or {})", names.join(", "))
    };
    format!("remove joint `{first}`{or}")
}

/// The joints whose equations the other constraints already impose (`over`: the constraints
/// of the over-determined part).
fn removable_joints<'a>(
    spec: &'a Spec,
    model: &Model,
    rows: &[Vec<usize>],
    structure: &Structure,
    over: &[usize],
) -> Vec<&'a Ident> {
    // The joints (and drivers) whose equations the others already impose, last declared
    // first: the likeliest to have been added by mistake.
    // A pin repeating an earlier one comes first, alone (its equations are the other's).
    let mut removable = redundancy::removable(model, rows, structure.rank, over);
    removable.reverse();
    if let Some(&(later, earlier)) = redundancy::repeated_pins(model, over).last() {
        removable = vec![later, earlier];
    }
    let ground = model.bodies.iter().filter(|b| b.ground).count();
    removable
        .iter()
        .filter_map(|&k| spec.joints.get(k.checked_sub(ground)?).map(|j| &j.name))
        .collect()
}

/// Whether the scene declares free degrees of freedom (which count with its drivers).
fn has_free(spec: &Spec) -> bool {
    spec.drivers.iter().any(|d| d.free_keyword().is_some())
}
