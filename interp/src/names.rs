//! The interpreter's name tables as `'static` [`Names`], which every `SolveError` carries so
//! that it names what failed wherever it is printed.
//!
//! A generated scene's tables are constants; an interpreted scene's are read at run time, so
//! they are leaked to become `'static`: a `SolveError` is `Copy` and borrows nothing, so it
//! cannot hold a reference-counted or borrowed table. To keep the leak bounded by what the
//! process reads rather than by how often it builds solvers, tables are interned: a scene
//! whose names equal an earlier one's (the same file loaded again, a test building a scene
//! many times, a fuzzer mutating numbers) reuses that scene's tables. The memory kept is
//! that of the distinct scenes' names, a few bytes per coordinate and equation, reachable
//! from the interner until the process exits.

use std::collections::HashMap;
use std::sync::{Mutex, PoisonError};

use mechgen_runtime::Names;

/// The tables in [`Names`] order: mechanism (one entry), coordinates, equations, parameters,
/// branches, markers, loads.
pub(crate) type Tables = [Vec<String>; 7];

/// The `'static` names for `tables`: those of an earlier scene with equal tables, or these,
/// leaked once.
pub(crate) fn intern(tables: Tables) -> &'static Names {
    static INTERNED: Mutex<Option<HashMap<Tables, &'static Names>>> = Mutex::new(None);
    // A panic elsewhere while the lock was held leaves a map that is still consistent.
    let mut interned = INTERNED.lock().unwrap_or_else(PoisonError::into_inner);
    let map = interned.get_or_insert_with(HashMap::new);
    if let Some(&names) = map.get(&tables) {
        return names;
    }
    let leak = |table: &[String]| -> &'static [&'static str] {
        let names: Vec<&'static str> = table
            .iter()
            .map(|name| &*Box::leak(name.clone().into_boxed_str()))
            .collect();
        Box::leak(names.into_boxed_slice())
    };
    let [
        mechanism,
        coordinates,
        equations,
        parameters,
        branches,
        markers,
        loads,
    ] = &tables;
    let names: &'static Names = Box::leak(Box::new(Names {
        mechanism: leak(mechanism).first().copied().unwrap_or(""),
        coordinates: leak(coordinates),
        equations: leak(equations),
        parameters: leak(parameters),
        branches: leak(branches),
        markers: leak(markers),
        loads: leak(loads),
    }));
    map.insert(tables, names);
    names
}

#[cfg(test)]
mod tests {
    use super::*;

    fn tables(mechanism: &str) -> Tables {
        let one = |s: &str| vec![s.to_owned()];
        [
            one(mechanism),
            vec!["crank.x".into(), "crank.y".into()],
            one("pin.x"),
            one("omega"),
            one("open"),
            Vec::new(),
            one("gas"),
        ]
    }

    #[test]
    fn equal_tables_are_kept_once() {
        let first = intern(tables("Interned"));
        let again = intern(tables("Interned"));
        assert!(std::ptr::eq(first, again));
        assert_eq!(first.mechanism, "Interned");
        assert_eq!(first.coordinate(1), Some("crank.y"));
        assert_eq!(first.load(0), Some("gas"));
        let other = intern(tables("Other"));
        assert!(!std::ptr::eq(first, other));
    }
}
