//! mechgen CLI library (placeholder).
