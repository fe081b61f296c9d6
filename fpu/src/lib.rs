//! √x in single precision as the reel MCU's FPU computes it, for the `tss-reel` core.
//!
//! The Cortex-M4F's FPU (FPv4-SP) has a square root instruction, VSQRT.F32: IEEE 754 correctly
//! rounded, one instruction. Stable `no_std` Rust does not reach it: `core` has no `f32::sqrt`
//! (rustc 1.95), and libm's `sqrtf` is an integer routine of about 75 instructions on the M4F.
//! This crate is the one place the core's arithmetic uses `unsafe`: an `asm!` block of three
//! instructions (the argument into an FPU register, VSQRT.F32, the result back), with no memory
//! access and the FPU register it uses declared clobbered. It is a crate of its own so that the
//! core keeps `#![forbid(unsafe_code)]`.
//!
//! On every other target (the host, where the simulator and the tests run the same core) the
//! root is libm's `sqrtf`, correctly rounded too: host and MCU compute the same bits, which
//! `tests/firmware_replay.rs` checks command by command, and the on-target tests check the
//! instruction against libm's double-precision root rounded to f32 (`tests/on_target.rs`).
//!
//! Measured: the flight step's worst case over the paper mission 813 → 788 instructions with
//! VSQRT where the core's Newton iteration on the reciprocal root (`fastmath::sqrt`, within one
//! ulp) took 23 and the registers it held (`scripts/bench-target`).
#![no_std]
#![deny(unsafe_code)]
#![warn(missing_docs)]

/// √x, correctly rounded (IEEE 754): +0 → +0, −0 → −0, +∞ → +∞, negatives and NaN → NaN.
#[inline(always)]
pub fn sqrt(x: f32) -> f32 {
    #[cfg(all(target_arch = "arm", target_abi = "eabihf"))]
    {
        vsqrt(x)
    }
    #[cfg(not(all(target_arch = "arm", target_abi = "eabihf")))]
    {
        libm::sqrtf(x)
    }
}

/// VSQRT.F32 on `x`. Every Arm hard-float ABI target has an FPU with it (VFPv2 and later).
///
/// The operand travels through a core register and s14, which the block declares clobbered:
/// rustc 1.95 accepts FPU register classes (`sreg`) only with its `vfp2` target feature, which
/// the single-precision FPU of thumbv7em-none-eabihf does not enable, but it accepts a named
/// FPU register as a clobber.
#[cfg(all(target_arch = "arm", target_abi = "eabihf"))]
#[inline(always)]
fn vsqrt(x: f32) -> f32 {
    let root: u32;
    // SAFETY: the block reads `x` from a core register and writes `root` to one, uses s14
    // (declared clobbered: the compiler keeps nothing there across it), touches no memory and
    // no stack, and VSQRT.F32 cannot trap (FPU exceptions are not enabled on the M4F: an
    // invalid operand gives the default NaN and sets a cumulative FPSCR flag, which nothing
    // reads).
    #[allow(unsafe_code)]
    unsafe {
        core::arch::asm!(
            "vmov s14, {x}",
            "vsqrt.f32 s14, s14",
            "vmov {root}, s14",
            x = in(reg) x.to_bits(),
            root = lateout(reg) root,
            out("s14") _,
            options(pure, nomem, nostack),
        );
    }
    f32::from_bits(root)
}

#[cfg(test)]
mod tests {
    extern crate std;
    use super::sqrt;

    #[test]
    fn special_values_are_ieee() {
        assert_eq!(sqrt(4.0), 2.0);
        assert_eq!(sqrt(0.0).to_bits(), 0.0_f32.to_bits());
        assert_eq!(sqrt(-0.0).to_bits(), (-0.0_f32).to_bits());
        assert_eq!(sqrt(f32::INFINITY), f32::INFINITY);
        assert!(sqrt(-1.0).is_nan());
        assert!(sqrt(f32::NAN).is_nan());
        assert!(sqrt(f32::NEG_INFINITY).is_nan());
    }

    #[test]
    fn correctly_rounded_over_a_sweep_of_the_positive_floats() {
        // Every 4099th bit pattern from the smallest subnormal to the largest finite float:
        // the root in f64, exact to 53 bits, rounded once to f32 is the correctly rounded one
        // (53 ≥ 2·24 + 2, so the double rounding is innocuous for √).
        for bits in (1..f32::MAX.to_bits()).step_by(4099) {
            let x = f32::from_bits(bits);
            let expected = (f64::from(x)).sqrt() as f32;
            assert_eq!(sqrt(x).to_bits(), expected.to_bits(), "√{x:e}");
        }
    }
}
