//! Emission: a scene as Rust items (`quote!`): the parameter struct and its constants, the
//! textbook functions (`impl Mechanism`: Φ, Φ_q, ν, γ over all coordinates), the solve structure
//! (`impl Structured`, in `plan`), the named body accessors, and the equations of motion of a
//! scene that carries them (`impl EquationsOfMotion`, in `motion`).
//!
//! Bodies are straight-line code (`body`): no loops, no allocation, no `std`, no `unsafe`;
//! elementary functions come from `::mechgen_runtime::codegen::math`. Zero entries are never computed:
//! an output with zeros is cleared once and only non-zeros are written.

mod body;
mod checks;
mod dispatch;
mod forces;
mod free;
mod lu;
mod markers;
mod motion;
mod plan;
mod stages;
mod step;
mod step_forces;

use std::cell::RefCell;
use std::collections::HashMap;

use proc_macro2::{Ident, Literal, TokenStream};
use quote::{format_ident, quote};

pub use body::f64_literal;
use body::{Context, Function, computed};

use crate::expr::{Arena, Id};
use crate::model::kinematics::Kinematics;
use crate::model::{Outputs, Unit};
use crate::plan::Scene;

/// Choices that shape the generated code without changing its meaning.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct CodegenOptions {
    /// Largest number of operations (DAG nodes plus output stores) one generated function body
    /// may hold; longer bodies are split into helper functions of about this size. rustc's
    /// compile time grows much faster than linearly in the size of one function, so huge scenes
    /// need this.
    pub max_function_size: usize,
    /// The naive baseline, for measuring what the lean emission saves: no constant folding or
    /// algebraic simplification (the scene is compiled into [`Arena::unsimplified`]), no shared
    /// sub-expressions (every use evaluated again) and no solve structure (one block, factored
    /// with partial pivoting). Never for production code.
    pub naive: bool,
    /// Emit the equations of motion (`mechgen_runtime::EquationsOfMotion`: the products with
    /// the mass matrix and the tangent stiffness and damping, and the energies) for a scene
    /// that computes forces: for linearising a prescribed motion or driving an integrator of
    /// one's own. Off by default: the code is exactly what it was without it.
    pub equations_of_motion: bool,
}

impl Default for CodegenOptions {
    fn default() -> Self {
        Self {
            max_function_size: 2_000,
            naive: false,
            equations_of_motion: false,
        }
    }
}

/// Emits the whole item set for a scene with default options (see [`emit_with`]).
pub fn emit(scene: &Scene) -> TokenStream {
    emit_with(scene, &CodegenOptions::default())
}

/// Emits the whole item set for a scene: the parameter struct, its constants, the `Mechanism`
/// and `Structured` implementations and the named body accessors.
pub fn emit_with(scene: &Scene, options: &CodegenOptions) -> TokenStream {
    let cx = Context {
        model: &scene.model,
        equations: scene.model.equation_names(),
        forces: scene.forces.as_ref(),
        markers: &scene.kinematics.markers,
        load_witnesses: &scene.load_witnesses,
        options,
        helpers: RefCell::new(Vec::new()),
    };
    let kin = &scene.kinematics;
    let parameters = cx.parameter_struct();
    let constants = cx.constants(kin);
    let mechanism = cx.mechanism_impl(kin);
    let structured = plan::structured_impl(&cx, &scene.plan, &scene.kernels);
    let accessors = cx.accessors();
    let force_accessors = cx.forces.map(|_| cx.force_accessors());
    let motion = scene.motion.as_ref().map(|eom| cx.motion_impl(eom));
    let dynamic = cx.dynamic_impl();
    // Split bodies' parts, collected while the functions above were generated.
    let helpers = cx.helpers.into_inner();
    let name = &scene.model.name;
    let helpers = (!helpers.is_empty()).then(|| {
        quote! {
            /// Parts of the kinematic functions, split to keep each function small enough for
            /// rustc (`CodegenOptions::max_function_size`).
            impl #name {
                #(#helpers)*
            }
        }
    });
    quote! {
        #parameters
        #constants
        #mechanism
        #structured
        #helpers
        #accessors
        #force_accessors
        #motion
        #dynamic
    }
}

impl Context<'_> {
    /// The parameter struct and its `Default`.
    fn parameter_struct(&self) -> TokenStream {
        let model = self.model;
        let (docs, vis, name) = (&model.docs, &model.vis, &model.name);
        let fields = model.params.iter().map(|p| {
            let (docs, name) = (&p.docs, &p.name);
            quote! { #(#docs)* pub #name: f64, }
        });
        let defaults = model.params.iter().map(|p| {
            let (name, value) = (&p.name, f64_literal(p.default));
            quote! { #name: #value, }
        });
        let derived = self.derived_accessors();
        let (free, free_default) = (self.free_field(), self.free_default());
        quote! {
            #(#docs)*
            #[derive(Debug, Clone, Copy, PartialEq)]
            #vis struct #name {
                #(#fields)*
                #free
            }

            impl ::core::default::Default for #name {
                fn default() -> Self {
                    Self { #(#defaults)* #free_default }
                }
            }

            #derived
        }
    }

    /// One method per derived parameter, computing it from the fields (so it follows them).
    fn derived_accessors(&self) -> TokenStream {
        let model = self.model;
        if model.derived.is_empty() {
            return TokenStream::new();
        }
        let methods = model.derived.iter().map(|d| {
            let (docs, name) = (&d.docs, &d.name);
            let body = if model.arena.is_zero(d.value) {
                quote!(0.0)
            } else {
                self.function(&[(TokenStream::new(), d.value)], TokenStream::new(), &computed())
                    .body
            };
            let doc = format!(
                " Derived parameter `{name}`: computed from the parameters (set those to change it)."
            );
            let separator = (!docs.is_empty()).then(|| quote!(#[doc = ""]));
            quote! {
                #(#docs)*
                #separator
                #[doc = #doc]
                pub fn #name(&self) -> f64 {
                    #body
                }
            }
        });
        let name = &model.name;
        quote! {
            impl #name {
                #(#methods)*
            }
        }
    }

    /// Names, index constants, units and the Jacobian's pattern.
    fn constants(&self, kin: &Kinematics) -> TokenStream {
        let model = self.model;
        let name = &model.name;
        let n = model.dim();
        let n_lit = idx(n);
        let coordinate_names = model.coordinate_names();
        let equation_names = model.equation_names();
        let param_names: Vec<String> = model.params.iter().map(|p| p.name.to_string()).collect();
        let param_count = idx(param_names.len());
        let coordinate_consts = coordinate_indices(&coordinate_names);
        let jacobian_count = idx(kin.jacobian.len());
        let pattern = kin.jacobian.iter().map(|e| {
            let (r, c) = (idx(e.row), idx(e.col));
            quote! { (#r, #c) }
        });
        let coordinate_units = unit_list(model.coordinate_units());
        let equation_units = unit_list(model.equation_units());
        let branch_names = self.branch_names();
        let reaction_names = self.forces.map(|_| self.reaction_names());
        let splines = self.spline_tables();
        let marker_names = self.marker_names();
        let names = self.names_table();
        let coordinate_doc = format!(
            " Coordinate names in q order ({n} = 3 × {} bodies).",
            model.bodies.len()
        );
        let equation_doc = format!(" Equation names in Φ order ({n} equations).");
        let pattern_doc = format!(
            " Structural non-zeros of Φ_q as (equation, coordinate), row-major: {jacobian_count} of {}.",
            n * n
        );
        quote! {
            impl #name {
                /// Number of coordinates (= number of equations).
                pub const DIM: usize = #n_lit;
                #[doc = #coordinate_doc]
                pub const COORDINATES: [&'static str; #n_lit] = [#(#coordinate_names),*];
                #[doc = #equation_doc]
                pub const EQUATIONS: [&'static str; #n_lit] = [#(#equation_names),*];
                /// Run-time parameter names, in declaration order.
                pub const PARAMETERS: [&'static str; #param_count] = [#(#param_names),*];
                #[doc = #pattern_doc]
                pub const JACOBIAN_PATTERN: [(usize, usize); #jacobian_count] = [#(#pattern),*];
                /// Physical dimension of each coordinate, in q order (x, y lengths, θ angles).
                pub const COORDINATE_UNITS: [::mechgen_runtime::Unit; #n_lit] = #coordinate_units;
                /// Physical dimension of each equation, in Φ order.
                pub const EQUATION_UNITS: [::mechgen_runtime::Unit; #n_lit] = #equation_units;
                #branch_names
                #reaction_names
                #splines
                #marker_names
                #names
                #coordinate_consts
            }
        }
    }

    /// `NAMES`: the tables above in one `'static` value, which the solver attaches to every
    /// error so that it names what failed; the scene's loads are listed here only.
    fn names_table(&self) -> TokenStream {
        let model = self.model;
        let name = model.name.to_string();
        let table = |present: bool, konst: TokenStream| {
            if present {
                quote!(&Self::#konst)
            } else {
                quote!(&[])
            }
        };
        let branches = table(!model.branches.is_empty(), quote!(BRANCHES));
        let markers = table(!model.marker_names().is_empty(), quote!(MARKERS));
        let loads = model.loads.iter().map(|l| l.name.as_str());
        quote! {
            /// Every name above, for errors (`mechgen_runtime::Mechanism::names`).
            pub const NAMES: ::mechgen_runtime::Names = ::mechgen_runtime::Names {
                mechanism: #name,
                coordinates: &Self::COORDINATES,
                equations: &Self::EQUATIONS,
                parameters: &Self::PARAMETERS,
                branches: #branches,
                markers: #markers,
                loads: &[#(#loads),*],
            };
        }
    }

    /// `impl Mechanism` (names, parameters, units, length scale, branches, guess, Φ, Φ_q and the
    /// rates the scene asked for) and the level markers `Velocities`/`Accelerations`.
    fn mechanism_impl(&self, kin: &Kinematics) -> TokenStream {
        let model = self.model;
        let name = &model.name;
        let n_lit = idx(model.dim());
        let naming_methods = self.naming_methods();
        let parameter_methods = self.parameter_methods();
        let unit_methods = self.unit_methods();
        let length_scale = self.length_scale(kin);
        let check_geometry = self.check_method(&kin.geometry, checks::Checks::Geometry);
        let check_physics = self.check_method(&kin.physics, checks::Checks::Physics);
        let branch_methods = self.branch_methods(kin);
        let equations = self.textbook_functions(kin);
        let force_methods = self.forces.map(|forces| self.force_methods(forces));
        let marker_methods = self.marker_methods(self.markers);
        let (outputs_variant, markers) = self.level_markers();
        quote! {
            impl ::mechgen_runtime::Mechanism for #name {
                type Dim = ::mechgen_runtime::nalgebra::Const<#n_lit>;
                #marker_methods
                #naming_methods
                #parameter_methods
                #unit_methods
                #length_scale

                #check_geometry

                #check_physics

                #branch_methods

                fn outputs(&self) -> ::mechgen_runtime::Outputs {
                    ::mechgen_runtime::Outputs::#outputs_variant
                }

                #equations
                #force_methods
            }

            #markers
        }
    }

    /// The `Outputs` variant of the scene's level and the marker traits it implements
    /// (`Velocities`, `Accelerations`, `Forces`).
    fn level_markers(&self) -> (TokenStream, TokenStream) {
        let name = &self.model.name;
        match self.model.outputs {
            Outputs::Positions => (quote!(Positions), TokenStream::new()),
            Outputs::Velocities => (
                quote!(Velocities),
                quote! { impl ::mechgen_runtime::Velocities for #name {} },
            ),
            Outputs::Accelerations => (
                quote!(Accelerations),
                quote! {
                    impl ::mechgen_runtime::Velocities for #name {}
                    impl ::mechgen_runtime::Accelerations for #name {}
                },
            ),
            Outputs::Forces => (
                quote!(Forces),
                quote! {
                    impl ::mechgen_runtime::Velocities for #name {}
                    impl ::mechgen_runtime::Accelerations for #name {}
                    impl ::mechgen_runtime::Forces for #name {}
                },
            ),
        }
    }

    /// `Mechanism`'s naming methods: `dim`, `names`, and the coordinates' and equations' names,
    /// read from the tables of [`Context::constants`].
    fn naming_methods(&self) -> TokenStream {
        let n_lit = idx(self.model.dim());
        quote! {
            fn dim(&self) -> Self::Dim {
                ::mechgen_runtime::nalgebra::Const::<#n_lit>
            }

            fn names(&self) -> &'static ::mechgen_runtime::Names {
                &Self::NAMES
            }

            fn coordinate_name(&self, index: usize) -> ::core::option::Option<&str> {
                Self::COORDINATES.get(index).copied()
            }

            fn equation_name(&self, index: usize) -> ::core::option::Option<&str> {
                Self::EQUATIONS.get(index).copied()
            }
        }
    }

    /// `Mechanism`'s parameter methods: count, names, reads by index and checked writes by
    /// name.
    fn parameter_methods(&self) -> TokenStream {
        let model = self.model;
        let param_count = idx(model.params.len());
        let param_reads = model.params.iter().enumerate().map(|(i, p)| {
            let (i, name) = (idx(i), &p.name);
            quote! { #i => ::core::option::Option::Some(self.#name), }
        });
        let param_writes = model.params.iter().map(|p| {
            let (name, key) = (&p.name, p.name.to_string());
            quote! {
            #key => {
                self.#name = value;
                ::core::result::Result::Ok(())
            }
            }
        });
        quote! {
            fn parameter_count(&self) -> usize {
                #param_count
            }

            fn parameter_name(&self, index: usize) -> ::core::option::Option<&str> {
                Self::PARAMETERS.get(index).copied()
            }

            fn parameter(&self, index: usize) -> ::core::option::Option<f64> {
                match index {
                    #(#param_reads)*
                    _ => ::core::option::Option::None,
                }
            }

            fn set_parameter<'a>(
                &'a mut self,
                name: &'a str,
                value: f64,
            ) -> ::core::result::Result<(), ::mechgen_runtime::ParameterError<'a>> {
                if !value.is_finite() && Self::PARAMETERS.contains(&name) {
                    return ::core::result::Result::Err(
                        ::mechgen_runtime::ParameterError::NonFinite { name, value },
                    );
                }
                match name {
                    #(#param_writes)*
                    _ => ::core::result::Result::Err(
                        ::mechgen_runtime::ParameterError::Unknown {
                            name,
                            declared: &Self::PARAMETERS,
                        },
                    ),
                }
            }
        }
    }

    /// `Mechanism`'s units of coordinates and equations, read from the tables of
    /// [`Context::constants`].
    fn unit_methods(&self) -> TokenStream {
        quote! {
            fn coordinate_unit(&self, index: usize) -> ::mechgen_runtime::Unit {
                Self::COORDINATE_UNITS
                    .get(index)
                    .copied()
                    .unwrap_or(::mechgen_runtime::Unit::Angle)
            }

            fn equation_unit(&self, index: usize) -> ::mechgen_runtime::Unit {
                Self::EQUATION_UNITS
                    .get(index)
                    .copied()
                    .unwrap_or(::mechgen_runtime::Unit::Angle)
            }
        }
    }

    /// The textbook functions over all coordinates: the initial guess, Φ, Φ_q, both in one
    /// pass, and ν and γ when the scene asked for them.
    fn textbook_functions(&self, kin: &Kinematics) -> TokenStream {
        let guess = {
            let (outputs, clear) = self.vector_writes(&kin.guess, quote!(q));
            self.function(&outputs, clear, &computed()).body
        };
        let constraints = self.constraint_functions(kin);
        let rates = self.rate_functions(kin);
        quote! {
            fn initial_guess(&self, q: &mut ::mechgen_runtime::Vector<Self::Dim>) {
                #guess
            }
            #constraints
            #rates
        }
    }

    /// `phi`, `jacobian` and `phi_and_jacobian`.
    fn constraint_functions(&self, kin: &Kinematics) -> TokenStream {
        let (vector, matrix) = (self.vector_type(), self.matrix_type());
        let out_vector = [("out", quote!(&mut #vector))];
        let q = [("q", quote!(&#vector))];
        let phi = {
            let (outputs, clear) = self.vector_writes(&kin.phi, quote!(out));
            self.bounded("phi", &outputs, clear, &out_vector, &q, &computed())
        };
        let jacobian = {
            let (outputs, clear) = self.jacobian_writes(kin, quote!(out));
            let outs = [("out", quote!(&mut #matrix))];
            self.bounded("jacobian", &outputs, clear, &outs, &q, &computed())
        };
        let phi_and_jacobian = {
            let (mut outputs, mut clear) = self.vector_writes(&kin.phi, quote!(phi));
            let (jac_outputs, jac_clear) = self.jacobian_writes(kin, quote!(jacobian));
            outputs.extend(jac_outputs);
            clear.extend(jac_clear);
            let outs = [
                ("phi", quote!(&mut #vector)),
                ("jacobian", quote!(&mut #matrix)),
            ];
            self.bounded("phi_and_jacobian", &outputs, clear, &outs, &q, &computed())
        };
        let phi = signature(&phi, "Φ(q, t)", quote!(phi), quote!(out: &mut #vector));
        let jacobian = signature(
            &jacobian,
            "Φ_q(q, t)",
            quote!(jacobian),
            quote!(out: &mut #matrix),
        );
        let phi_and_jacobian = signature(
            &phi_and_jacobian,
            "Φ and Φ_q in one pass, sharing sub-expressions",
            quote!(phi_and_jacobian),
            quote!(phi: &mut #vector, jacobian: &mut #matrix),
        );
        quote! {
            #phi
            #jacobian
            #phi_and_jacobian
        }
    }

    /// `nu` and `gamma`, each when the scene asked for it.
    fn rate_functions(&self, kin: &Kinematics) -> TokenStream {
        let vector = self.vector_type();
        let out_vector = [("out", quote!(&mut #vector))];
        let q = [("q", quote!(&#vector))];
        let nu = kin.nu.as_deref().map(|nu| {
            let (outputs, clear) = self.vector_writes(nu, quote!(out));
            let f = self.bounded("nu", &outputs, clear, &out_vector, &q, &computed());
            signature(&f, "ν = −Φ_t", quote!(nu), quote!(out: &mut #vector))
        });
        let gamma = kin.gamma.as_deref().map(|gamma| {
            let (outputs, clear) = self.vector_writes(gamma, quote!(out));
            let q_qd = [("q", quote!(&#vector)), ("qd", quote!(&#vector))];
            let f = self.bounded("gamma", &outputs, clear, &out_vector, &q_qd, &computed());
            let qd = &f.args.qd;
            signature_with(
                &f,
                "γ(q, q̇, t)",
                quote!(gamma),
                quote!(#qd: &#vector,),
                quote!(out: &mut #vector),
            )
        });
        quote! {
            #nu
            #gamma
        }
    }

    /// `::mechgen_runtime::Matrix<Const<N>>` for this scene.
    fn matrix_type(&self) -> TokenStream {
        let n = idx(self.model.dim());
        quote!(::mechgen_runtime::Matrix<::mechgen_runtime::nalgebra::Const<#n>>)
    }

    /// The writes of `values` into `target[i]`, and the clear they need (some are zero).
    fn vector_writes(
        &self,
        values: &[Id],
        target: TokenStream,
    ) -> (Vec<(TokenStream, Id)>, TokenStream) {
        let clear = clear_if_sparse(&self.model.arena, values, &target);
        (vector_outputs(values, &target), clear)
    }

    /// The writes of Φ_q's structural non-zeros into `target[(r, c)]`, and the clear they need
    /// (some entries are not structural).
    fn jacobian_writes(
        &self,
        kin: &Kinematics,
        target: TokenStream,
    ) -> (Vec<(TokenStream, Id)>, TokenStream) {
        let n = self.model.dim();
        let outputs: Vec<(TokenStream, Id)> = kin
            .jacobian
            .iter()
            .map(|e| (matrix_target(&target, e.row, e.col), e.value))
            .collect();
        let clear = if kin.jacobian.len() < n * n {
            quote! { #target.as_mut_slice().fill(0.0); }
        } else {
            TokenStream::new()
        };
        (outputs, clear)
    }

    /// Named access to the bodies of a solved state: `state.piston().x`.
    fn accessors(&self) -> TokenStream {
        let model = self.model;
        let (vis, name) = (&model.vis, &model.name);
        let bodies_trait = format_ident!("{}Bodies", name);
        let bodies_doc = format!(
            " Named access to the bodies of a solved [`{name}`] state: `state.{}().x`.",
            model
                .bodies
                .iter()
                .find(|b| !b.ground)
                .map_or("body".to_owned(), |b| b.name.to_string())
        );
        let (view, what) = match model.outputs {
            Outputs::Positions => (quote!(Pose), "Pose"),
            Outputs::Velocities => (quote!(PoseVelocity), "Pose and velocity"),
            Outputs::Accelerations | Outputs::Forces => {
                (quote!(BodyState), "Pose, velocity and acceleration")
            }
        };
        let declarations = model.bodies.iter().map(|b| {
            let ident = &b.name;
            let docs = if b.docs.is_empty() {
                let doc = format!(" {what} of `{ident}`.");
                quote! { #[doc = #doc] }
            } else {
                let docs = &b.docs;
                quote! { #(#docs)* }
            };
            quote! { #docs fn #ident(&self) -> ::mechgen_runtime::#view; }
        });
        let (marker_declarations, marker_implementations) = self.marker_accessors();
        let implementations =
            (model.bodies.iter().enumerate()).map(|(i, b)| self.body_accessor(i, &b.name, &view));
        quote! {
            #[doc = #bodies_doc]
            #vis trait #bodies_trait {
                #(#declarations)*
                #(#marker_declarations)*
            }

            impl #bodies_trait for ::mechgen_runtime::State<#name> {
                #(#implementations)*
                #(#marker_implementations)*
            }
        }
    }

    /// The accessor of body `i` on `State`: its pose and the rates the scene computes, as the
    /// `view` type.
    fn body_accessor(&self, i: usize, ident: &Ident, view: &TokenStream) -> TokenStream {
        let outputs = self.model.outputs;
        let [x, y, th] = [3 * i, 3 * i + 1, 3 * i + 2].map(idx);
        let velocity = (outputs >= Outputs::Velocities).then(|| {
            quote! { x_dot: self.qd()[#x], y_dot: self.qd()[#y], theta_dot: self.qd()[#th], }
        });
        let acceleration = (outputs >= Outputs::Accelerations).then(|| {
            quote! {
                x_ddot: self.qdd()[#x], y_ddot: self.qdd()[#y], theta_ddot: self.qdd()[#th],
            }
        });
        quote! {
            fn #ident(&self) -> ::mechgen_runtime::#view {
                ::mechgen_runtime::#view {
                    x: self.q[#x], y: self.q[#y], theta: self.q[#th],
                    #velocity
                    #acceleration
                }
            }
        }
    }
}

/// One `pub const NAME_X: usize` per coordinate: its index in q.
fn coordinate_indices(coordinate_names: &[String]) -> TokenStream {
    let consts = coordinate_names.iter().enumerate().map(|(i, c)| {
        let ident = format_ident!("{}", c.replace('.', "_").to_uppercase());
        let doc = format!(" Index of `{c}` in q.");
        let i = idx(i);
        quote! { #[doc = #doc] pub const #ident: usize = #i; }
    });
    quote!(#(#consts)*)
}

/// `[::mechgen_runtime::Unit::Length, …]`: a units table.
fn unit_list(units: Vec<Unit>) -> TokenStream {
    let units = units.into_iter().map(|u| {
        let variant = format_ident!("{}", u.name());
        quote!(::mechgen_runtime::Unit::#variant)
    });
    quote!([#(#units),*])
}

/// A textbook function's item: doc, signature (`q`, `q̇` if the function takes it, `t`, then
/// the outputs `rest`, named as the body reads them) and body.
fn signature(f: &Function, what: &str, name: TokenStream, rest: TokenStream) -> TokenStream {
    signature_with(f, what, name, TokenStream::new(), rest)
}

fn signature_with(
    f: &Function,
    what: &str,
    name: TokenStream,
    qd: TokenStream,
    rest: TokenStream,
) -> TokenStream {
    let (doc, body) = (f.doc(what), &f.body);
    let (q, t) = (&f.args.q, &f.args.t);
    quote! {
        #doc
        fn #name(
            &self,
            #q: &::mechgen_runtime::Vector<Self::Dim>,
            #qd
            #t: f64,
            #rest
        ) {
            #body
        }
    }
}

fn vector_outputs(values: &[Id], target: &TokenStream) -> Vec<(TokenStream, Id)> {
    values
        .iter()
        .enumerate()
        .map(|(i, &id)| {
            let i = idx(i);
            (quote!(#target[#i]), id)
        })
        .collect()
}

/// An index or size literal without a `usize` suffix (generated code is read by people).
fn idx(i: usize) -> Literal {
    Literal::usize_unsuffixed(i)
}

/// `out[(r, c)]` for a Jacobian entry.
fn matrix_target(target: &TokenStream, row: usize, col: usize) -> TokenStream {
    let (r, c) = (idx(row), idx(col));
    quote!(#target[(#r, #c)])
}

/// Clears `target` if some of `values` are identically zero (only non-zeros are written).
fn clear_if_sparse(arena: &Arena, values: &[Id], target: &TokenStream) -> TokenStream {
    if values.iter().any(|&v| arena.is_zero(v)) {
        // Slice fill: nalgebra's `fill` goes element by element, ~18× slower for a 15 × 15.
        quote! { #target.as_mut_slice().fill(0.0); }
    } else {
        TokenStream::new()
    }
}

impl Context<'_> {
    /// `length_scale`: the constant lengths folded into one literal, the parameter-dependent
    /// ones evaluated and folded in with `max(|v|)`, in the order of
    /// [`LengthScale::evaluate`](crate::model::kinematics::LengthScale::evaluate).
    fn length_scale(&self, kin: &Kinematics) -> TokenStream {
        let scale = &kin.length_scale;
        let constant = f64_literal(scale.constant);
        let doc = format!(
            " The largest magnitude among the scene's geometric lengths (body-fixed points, \
             distances, ground positions){}.",
            if scale.dependent.is_empty() {
                String::new()
            } else {
                format!(
                    ": the constant ones folded into `{}`, {} parameter-dependent one{} \
                     evaluated with the current parameters",
                    scale.constant,
                    scale.dependent.len(),
                    if scale.dependent.len() == 1 { "" } else { "s" }
                )
            }
        );
        let body = if scale.dependent.is_empty() {
            constant
        } else {
            let (names, evaluated) = self.bind_locals("length", &scale.dependent);
            quote! {
                #evaluated
                let scale: f64 = #constant;
                scale #(.max(#names.abs()))*
            }
        };
        quote! {
            #[doc = #doc]
            fn length_scale(&self) -> f64 {
                #body
            }
        }
    }

    /// Statements binding each of `ids` (expressions in parameters) to a local `{prefix}{k}`,
    /// sharing sub-expressions, and the locals' names: what `length_scale` and the parameter checks
    /// evaluate with the current parameters.
    pub(super) fn bind_locals(&self, prefix: &str, ids: &[Id]) -> (Vec<Ident>, TokenStream) {
        let names: Vec<Ident> = (0..ids.len())
            .map(|k| format_ident!("{}{}", prefix, k))
            .collect();
        let outputs: Vec<(TokenStream, Id)> = names
            .iter()
            .zip(ids)
            .map(|(name, &id)| (quote!(let #name), id))
            .collect();
        // The function body skips zero outputs; their locals are still read.
        let zeros = names
            .iter()
            .zip(ids)
            .filter(|&(_, &id)| self.arena().is_zero(id))
            .map(|(name, _)| quote! { let #name = 0.0f64; });
        let zeros: Vec<TokenStream> = zeros.collect();
        let body = self
            .function(&outputs, TokenStream::new(), &computed())
            .body;
        (names, quote! { #body #(#zeros)* })
    }

    /// The spline tables of the scene's motion laws, as `SPLINE_k` constants the function
    /// bodies evaluate (`Self::SPLINE_k.eval(x, order)`); nothing for a scene without splines.
    fn spline_tables(&self) -> TokenStream {
        let tables = self
            .arena()
            .spline_tables()
            .iter()
            .enumerate()
            .map(|(k, table)| {
                let name = format_ident!("SPLINE_{}", k);
                let knots = table.knots.iter().map(|&x| f64_literal(x));
                let segments = table.segments.iter().map(|segment| {
                    let coefficients = segment.iter().map(|&c| f64_literal(c));
                    quote!([#(#coefficients),*])
                });
                let doc = format!(
                    " Motion law {k}: the natural cubic spline through {} points.",
                    table.knots.len()
                );
                quote! {
                    #[doc = #doc]
                    #[allow(dead_code)]
                    const #name: ::mechgen_runtime::codegen::math::Spline<'static> =
                        ::mechgen_runtime::codegen::math::Spline {
                            knots: &[#(#knots),*],
                            segments: &[#(#segments),*],
                        };
                }
            });
        quote!(#(#tables)*)
    }

    /// The `BRANCHES` names (nothing for a scene without branch invariants).
    fn branch_names(&self) -> TokenStream {
        let branches = &self.model.branches;
        if branches.is_empty() {
            return TokenStream::new();
        }
        let names = branches.iter().map(|b| b.name.as_str());
        let count = idx(branches.len());
        let docs = branches.iter().map(|b| {
            let line = format!(" - `{}`: `{}`", b.name, self.model.describe_branch(b));
            quote! { #[doc = #line] }
        });
        quote! {
            /// Branch invariants, in declaration order:
            ///
            #(#docs)*
            pub const BRANCHES: [&'static str; #count] = [#(#names),*];
        }
    }

    /// The `branch_*` methods, or nothing for a scene without branch invariants (the trait's
    /// defaults then say "none").
    fn branch_methods(&self, kin: &Kinematics) -> TokenStream {
        if kin.branches.is_empty() {
            return TokenStream::new();
        }
        let count = idx(kin.branches.len());
        let computed = computed();
        let (arms, q, _) = self.branch_arms(kin.branches.iter().map(|&id| (id, &computed)));
        quote! {
            fn branch_count(&self) -> usize {
                #count
            }

            fn branch_name(&self, index: usize) -> ::core::option::Option<&str> {
                Self::BRANCHES.get(index).copied()
            }

            /// The invariant's value, signed to be positive on the declared branch.
            fn branch_value(
                &self,
                index: usize,
                #q: &::mechgen_runtime::Vector<Self::Dim>,
            ) -> f64 {
                match index {
                    #(#arms)*
                    _ => f64::NAN,
                }
            }
        }
    }
}

impl Context<'_> {
    /// The `match` arms of a method giving each branch invariant's value (`0.0` for one that
    /// folded to zero), each read with its cached sines and cosines; and the names of its `q`
    /// and `trig` parameters (with a leading underscore when no arm reads them).
    pub(super) fn branch_arms<'c>(
        &self,
        branches: impl Iterator<Item = (Id, &'c HashMap<Id, usize>)>,
    ) -> (Vec<TokenStream>, Ident, Ident) {
        let (mut reads_q, mut reads_trig) = (false, false);
        let arms = branches
            .enumerate()
            .map(|(i, (id, cached))| {
                let value = if self.arena().is_zero(id) {
                    quote!(0.0)
                } else {
                    let f = self.function(&[(TokenStream::new(), id)], TokenStream::new(), cached);
                    reads_q |= f.args.q == "q";
                    reads_trig |= f.args.trig == "trig";
                    let body = f.body;
                    quote! { { #body } }
                };
                let i = idx(i);
                quote! { #i => #value, }
            })
            .collect();
        let name = |reads: bool, name: &str| {
            if reads {
                format_ident!("{}", name)
            } else {
                format_ident!("_{}", name)
            }
        };
        (arms, name(reads_q, "q"), name(reads_trig, "trig"))
    }
}
