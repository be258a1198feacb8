//! mechgen CLI (placeholder).
fn main() {}
