//! The stack high-water mark of a call: paint the free stack below the caller with a pattern,
//! run the call, and find the deepest word that no longer holds the pattern.
//!
//! The only `unsafe` of the firmware: raw writes and reads of the free stack, which no Rust object
//! owns.
#![allow(unsafe_code)]

use core::ptr;

/// A word a call is unlikely to leave behind (not 0, not a RAM or flash address, not a small
/// integer or a common float).
const PATTERN: u32 = 0xA5C3_5A3C;

/// Bytes below the stack pointer that are painted: far more than a step needs; a call reaching
/// the bottom is reported, not underestimated.
const WINDOW: usize = 32 * 1024;

unsafe extern "C" {
    /// End of `.bss`/`.uninit` (cortex-m-rt's `link.x`): the stack may grow down to here.
    safe static _stack_end: u32;
}

/// The free stack below the current stack pointer, painted.
pub struct Painted {
    top: usize,
    bottom: usize,
}

/// The call reached the bottom of the painted window (or the window did not fit above `.bss`).
#[derive(Debug)]
pub struct Overflowed;

impl Painted {
    /// Paints the [`WINDOW`] bytes below the caller's stack pointer.
    ///
    /// Inlined, so the stack pointer read is the caller's, and everything below it is free: no
    /// interrupt is enabled, so nothing else uses the stack.
    #[inline(always)]
    pub fn below_caller() -> Result<Self, Overflowed> {
        let top = cortex_m::register::msp::read() as usize & !3;
        let floor = ptr::addr_of!(_stack_end) as usize;
        let bottom = top
            .checked_sub(WINDOW)
            .filter(|&b| b >= floor)
            .ok_or(Overflowed)?;
        for address in (bottom..top).step_by(4) {
            // SAFETY: `bottom..top` is below the stack pointer and above the end of `.bss`
            // (checked above): RAM that no live object occupies, 4-byte aligned.
            unsafe { ptr::write_volatile(address as *mut u32, PATTERN) };
        }
        Ok(Self { top, bottom })
    }

    /// Bytes of the window that were written since [`Painted::below_caller`]: the depth that
    /// calls made from the painting frame reached below its stack pointer.
    pub fn high_water(&self) -> Result<usize, Overflowed> {
        let touched = (self.bottom..self.top).step_by(4).find(|&address| {
            // SAFETY: as in `below_caller`: free, aligned RAM inside the window.
            unsafe { ptr::read_volatile(address as *const u32) != PATTERN }
        });
        match touched {
            Some(address) if address == self.bottom => Err(Overflowed),
            Some(address) => Ok(self.top - address),
            None => Ok(0),
        }
    }
}
