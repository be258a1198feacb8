//! The run-time checks of values written in parameters (`crate::model::geometry`, `crate::model::physics`):
//! `check_geometry` and `check_physics`, each evaluating its values with the current
//! parameters and checking them against their rules in declaration order; nothing for a scene
//! whose values are constant.

use proc_macro2::TokenStream;
use quote::{format_ident, quote};

use super::body::Context;
use super::idx;
use crate::model::geometry::Check;
use crate::model::physics::Subject;

/// What a check names, as the runtime's checking function takes it.
pub(super) trait Named: Copy {
    /// The checking function's subject argument.
    fn tokens(self) -> TokenStream;
}

/// Geometry names the constraint's first equation.
impl Named for usize {
    fn tokens(self) -> TokenStream {
        let e = idx(self);
        quote!(#e)
    }
}

/// Mass properties and load constants name their body or load.
impl Named for Subject {
    fn tokens(self) -> TokenStream {
        match self {
            Subject::Body(b) => {
                let b = idx(b);
                quote!(::mechgen_runtime::Subject::Body(#b))
            }
            Subject::Load(l) => {
                let l = idx(l);
                quote!(::mechgen_runtime::Subject::Load(#l))
            }
        }
    }
}

/// The two lists of checks, each behind its own `Mechanism` method and fault type.
#[derive(Clone, Copy)]
pub(super) enum Checks {
    /// The geometry of the constraints (`GeometryFault`, naming an equation).
    Geometry,
    /// The mass properties and load constants (`PhysicsFault`, naming a body or load).
    Physics,
}

impl Context<'_> {
    /// The `Mechanism` method checking `checks` (the runtime's default, nothing to check, when
    /// there are none).
    pub(super) fn check_method<S: Named>(&self, checks: &[Check<S>], kind: Checks) -> TokenStream {
        if checks.is_empty() {
            return TokenStream::new();
        }
        let (method, fault, local, what, rules) = match kind {
            Checks::Geometry => (
                "check_geometry",
                "GeometryFault",
                "value",
                "the geometry written in parameters",
                "the runtime's rules",
            ),
            Checks::Physics => (
                "check_physics",
                "PhysicsFault",
                "physics",
                "the mass properties and load constants written in parameters",
                "the rules constants obey",
            ),
        };
        let values: Vec<_> = checks.iter().map(|c| c.value).collect();
        let (names, evaluated) = self.bind_locals(local, &values);
        let check = format_ident!("{}", method);
        let tests = names.iter().zip(checks).map(|(name, c)| {
            let requirement = format_ident!("{}", c.requirement.name());
            let subject = c.subject.tokens();
            let parameter = idx(c.parameter);
            quote! {
                ::mechgen_runtime::codegen::#check(
                    #name,
                    ::mechgen_runtime::Requirement::#requirement,
                    #subject,
                    #parameter,
                )?;
            }
        });
        let doc = format!(
            " Checks {what} ({} value{}) against {rules}, with the current parameters.",
            checks.len(),
            if checks.len() == 1 { "" } else { "s" },
        );
        let fault = format_ident!("{}", fault);
        quote! {
            #[doc = #doc]
            fn #check(
                &self,
            ) -> ::core::result::Result<(), ::mechgen_runtime::#fault> {
                #evaluated
                #(#tests)*
                ::core::result::Result::Ok(())
            }
        }
    }
}
