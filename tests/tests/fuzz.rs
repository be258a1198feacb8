//! The deterministic mutation corpus of [`mechgen_tests::fuzzing`] (see its docs for what each
//! mutant must satisfy), run in CI: [`MUTANTS`] mutants per example scene.
//!
//! For a longer run on a developer's machine, set `MECHGEN_FUZZ_MUTANTS` (per scene) and
//! `MECHGEN_FUZZ_SEED`, e.g.
//! `MECHGEN_FUZZ_MUTANTS=100000 cargo test --release -p mechgen-tests --test fuzz -- --nocapture`,
//! or run the coverage-guided `cargo fuzz` targets in `fuzz/`.

use mechgen_tests::fuzzing::{Rng, SCENES, Tally, mutate, run};

/// Mutants per scene in CI (10,500 in all, over the seven seed scenes).
const MUTANTS: usize = 1500;

#[test]
fn mutated_example_scenes_end_in_an_answer_or_a_typed_error() {
    let setting = |name: &str, default: u64| {
        std::env::var(name)
            .ok()
            .and_then(|v| v.parse().ok())
            .unwrap_or(default)
    };
    let mutants = setting("MECHGEN_FUZZ_MUTANTS", MUTANTS as u64);
    let seed = setting("MECHGEN_FUZZ_SEED", 0x5EED);
    let mut tally = Tally::default();
    for (k, scene) in SCENES.iter().enumerate() {
        let mut rng = Rng(seed + k as u64);
        for _ in 0..mutants {
            let mutant = mutate(scene, &mut rng);
            let outcome = std::panic::catch_unwind(|| {
                let mut local = Tally::default();
                run(&mutant, &mut local);
                local
            });
            match outcome {
                Ok(local) => tally.add(&local),
                Err(_) => panic!("mutant panicked or broke an invariant:\n{mutant}"),
            }
        }
    }
    eprintln!("fuzz corpus: {tally:?}");
    // The corpus exercises every outcome.
    assert!(tally.compile_errors > 0 && tally.assembly_errors > 0 && tally.solved > 0);
}
