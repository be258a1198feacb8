//! One traced state as text without `core::fmt`: decimal step numbers and each `f64` as the 16
//! hex digits of its bits, so that equal lines mean bit-identical values and the firmware links
//! no formatting code for them.

/// Bytes a line can hold: a label, a step number and 64 values (the seed's lines hold 46 and
/// 61).
const CAPACITY: usize = 32 + 64 * 17;

/// A line too long for [`Line`]'s fixed buffer.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Overflow;

/// A line of text in a fixed buffer: `label k hex hex …\n`.
pub struct Line {
    bytes: [u8; CAPACITY],
    len: usize,
    overflowed: bool,
}

impl Line {
    /// Starts a line with `label` and the step number `k`.
    pub fn new(label: &str, k: usize) -> Self {
        let mut line = Self::text(label);
        line.push_decimal(k);
        line
    }

    /// Starts a line with `text`.
    pub fn text(text: &str) -> Self {
        let mut line = Self {
            bytes: [0; CAPACITY],
            len: 0,
            overflowed: false,
        };
        line.push_bytes(text.as_bytes());
        line
    }

    /// Appends ` ` and the 16 hex digits of `x`'s bits.
    pub fn push(&mut self, x: f64) {
        let bits = x.to_bits();
        let mut digits = [b' '; 17];
        for (i, digit) in digits[1..].iter_mut().enumerate() {
            *digit = hex_digit((bits >> (60 - 4 * i)) & 0xf);
        }
        self.push_bytes(&digits);
    }

    /// Appends every value of `values`.
    pub fn extend<'a>(&mut self, values: impl IntoIterator<Item = &'a f64>) {
        for &x in values {
            self.push(x);
        }
    }

    /// Appends ` ` and `n` in decimal.
    pub fn push_decimal(&mut self, mut n: usize) {
        let mut digits = [0u8; 21];
        let mut start = digits.len();
        loop {
            start -= 1;
            digits[start] = b'0' + (n % 10) as u8;
            n /= 10;
            if n == 0 {
                break;
            }
        }
        start -= 1;
        digits[start] = b' ';
        self.push_bytes(&digits[start..]);
    }

    /// Appends raw text.
    pub fn push_bytes(&mut self, bytes: &[u8]) {
        match self.bytes.get_mut(self.len..self.len + bytes.len()) {
            Some(room) => {
                room.copy_from_slice(bytes);
                self.len += bytes.len();
            }
            None => self.overflowed = true,
        }
    }

    /// The line with its `\n`.
    ///
    /// # Errors
    /// [`Overflow`] if anything pushed did not fit.
    pub fn finish(&mut self) -> Result<&[u8], Overflow> {
        self.push_bytes(b"\n");
        if self.overflowed {
            return Err(Overflow);
        }
        Ok(&self.bytes[..self.len])
    }
}

fn hex_digit(nibble: u64) -> u8 {
    b"0123456789abcdef"[nibble as usize]
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn values_are_their_bits_in_hex() {
        let mut line = Line::new("kinematics", 42);
        line.push(1.0);
        line.push(-0.0);
        line.push(f64::from_bits(0x0123_4567_89ab_cdef));
        assert_eq!(
            line.finish(),
            Ok(&b"kinematics 42 3ff0000000000000 8000000000000000 0123456789abcdef\n"[..])
        );
    }

    #[test]
    fn zero_and_large_step_numbers() {
        let mut line = Line::new("a", 0);
        line.push_decimal(usize::MAX);
        let text = line.finish().map(|b| core::str::from_utf8(b).ok());
        assert_eq!(text, Ok(Some("a 0 18446744073709551615\n")));
    }

    #[test]
    fn a_full_line_is_an_error_not_a_truncation() {
        let mut line = Line::new("x", 1);
        for _ in 0..CAPACITY / 17 + 1 {
            line.push(0.5);
        }
        assert_eq!(line.finish(), Err(Overflow));
    }
}
