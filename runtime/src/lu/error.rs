//! Why a factorisation or a solve failed.

/// Why a factorisation or solve failed.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum LuError {
    /// Column `column` has no pivot above the tolerance among the rows not yet eliminated.
    ///
    /// `row` is the original index of the remaining row whose eliminated part is smallest: the
    /// likeliest redundant or conflicting equation. `pivot` is the largest candidate magnitude.
    Singular {
        /// Original row (equation) index.
        row: usize,
        /// Column (coordinate) index.
        column: usize,
        /// Magnitude of the best available pivot.
        pivot: f64,
    },
    /// The matrix has a NaN or infinite entry (also: a scale that is not finite and positive,
    /// or scaling that overflowed).
    NonFinite,
    /// `solve_in_place` was called without a successful `factor` since the last failure.
    NotFactored,
    /// A matrix or vector does not have the size of the factorisation.
    DimensionMismatch {
        /// The factorisation's size.
        expected: usize,
        /// The size that was passed.
        found: usize,
    },
}

impl core::fmt::Display for LuError {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        match self {
            Self::Singular { row, column, pivot } => write!(
                f,
                "singular matrix: no usable pivot in column {column} (row {row}, |pivot| = {pivot:e})"
            ),
            Self::NonFinite => f.write_str("matrix has a NaN or infinite entry"),
            Self::NotFactored => f.write_str("no successful factorisation to solve with"),
            Self::DimensionMismatch { expected, found } => {
                write!(
                    f,
                    "size {found} does not match the factorisation's {expected}"
                )
            }
        }
    }
}

impl core::error::Error for LuError {}
