//! The per-block determinant signature ([`crate::Convergence::block_signs`]): one 64-bit code
//! per block, XORed over the blocks whose determinant is negative, so that two states can be
//! compared block by block in a fixed size and without allocating, however many blocks the
//! scene has. The solver builds it; stepping and the crossing search compare it.

/// The code of stage `stage` in [`crate::Convergence::block_signs`]: the splitmix64 finaliser
/// of the index, a bijection of `u64`, so that distinct stages get distinct codes and the
/// signatures of two sets of blocks that differ in one or two blocks always differ. Zero only
/// for one index far beyond any scene (checked below for the first 2²⁰ stages).
pub(crate) fn block_code(stage: usize) -> u64 {
    let mut z = (stage as u64).wrapping_add(0x9E37_79B9_7F4A_7C15);
    z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
    z ^ (z >> 31)
}

#[cfg(test)]
mod tests {
    use super::block_code;

    #[test]
    fn block_codes_are_non_zero_and_no_two_cancel() {
        // XOR of two codes is zero only for equal codes: a bijection makes them distinct.
        let mut seen = [0_u64; 1 << 12];
        for (stage, code) in seen.iter_mut().enumerate() {
            *code = block_code(stage);
        }
        seen.sort_unstable();
        assert!(seen.windows(2).all(|w| w[0] != w[1]));
        assert!((0..1 << 20).all(|stage| block_code(stage) != 0));
    }
}
