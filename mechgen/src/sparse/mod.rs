//! Algorithms on sparsity patterns, shared by the checker and the solve structure: bipartite
//! matching and strongly connected components ([`graph`]), and the static sparse LU whose pivot
//! order is chosen at generation time ([`factor`]).

pub mod factor;
pub mod graph;
