//! Structure-aware fuzzing: the input chooses an example scene and seeds a chain of mutations
//! of it (the CI corpus's mutations, steered by coverage instead of a fixed seed); each mutant
//! must end in a compile error, a typed error, or states whose constraints hold, within the
//! evaluation budget (`mechgen_tests::fuzzing::run` panics otherwise).
#![no_main]

use libfuzzer_sys::fuzz_target;
use mechgen_tests::fuzzing::{Rng, SCENES, Tally, mutate, run};

fuzz_target!(|data: &[u8]| {
    let Some((&choice, rest)) = data.split_first() else {
        return;
    };
    let mut seed = [0u8; 8];
    for (s, d) in seed.iter_mut().zip(rest) {
        *s = *d;
    }
    let mut rng = Rng(u64::from_le_bytes(seed));
    let mut scene = SCENES[usize::from(choice) % SCENES.len()].to_owned();
    // One to four mutations stacked.
    for _ in 0..1 + (choice as usize / SCENES.len()) % 4 {
        scene = mutate(&scene, &mut rng);
    }
    run(&scene, &mut Tally::default());
});
