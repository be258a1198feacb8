//! Free-form fuzzing of the `.mech` front end and everything behind it: any UTF-8 text is
//! parsed and checked, and a scene that compiles is assembled and stepped; the same invariants
//! as the mutation corpus hold (`mechgen_tests::fuzzing::run` panics otherwise). Seed the
//! corpus with `examples/scenes/*.mech`.
#![no_main]

use libfuzzer_sys::fuzz_target;
use mechgen_tests::fuzzing::{Tally, run};

fuzz_target!(|data: &[u8]| {
    if let Ok(source) = std::str::from_utf8(data) {
        run(source, &mut Tally::default());
    }
});
