//! `check_physics` for a scene whose mass properties or load constants are written in
//! parameters ([`crate::physics`]); nothing for any other scene.

use proc_macro2::TokenStream;
use quote::{format_ident, quote};

use super::body::Context;
use super::idx;
use crate::kinematics::Kinematics;
use crate::physics::Subject;

impl Context<'_> {
    /// `check_physics`: each value evaluated with the current parameters and checked against
    /// its rule, in declaration order.
    pub(super) fn check_physics(&self, kin: &Kinematics) -> TokenStream {
        let checks = &kin.physics;
        if checks.is_empty() {
            return TokenStream::new();
        }
        let values: Vec<_> = checks.iter().map(|c| c.value).collect();
        let (names, evaluated) = self.bind_locals("physics", &values);
        let tests = names.iter().zip(checks).map(|(name, c)| {
            let requirement = format_ident!("{}", c.requirement.name());
            let subject = match c.subject {
                Subject::Body(b) => {
                    let b = idx(b);
                    quote!(::mechgen_runtime::Subject::Body(#b))
                }
                Subject::Load(l) => {
                    let l = idx(l);
                    quote!(::mechgen_runtime::Subject::Load(#l))
                }
            };
            let parameter = idx(c.parameter);
            quote! {
                ::mechgen_runtime::codegen::check_physics(
                    #name,
                    ::mechgen_runtime::Requirement::#requirement,
                    #subject,
                    #parameter,
                )?;
            }
        });
        let doc = format!(
            " Checks the mass properties and load constants written in parameters ({} \
             value{}) against the rules constants obey, with the current parameters.",
            checks.len(),
            if checks.len() == 1 { "" } else { "s" },
        );
        quote! {
            #[doc = #doc]
            fn check_physics(
                &self,
            ) -> ::core::result::Result<(), ::mechgen_runtime::PhysicsFault> {
                #evaluated
                #(#tests)*
                ::core::result::Result::Ok(())
            }
        }
    }
}
