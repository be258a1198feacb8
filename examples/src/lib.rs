//! Example scenes (placeholder).
