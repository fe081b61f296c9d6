//! A small deterministic random generator for the simulator: every noise stream of the
//! sensors (`crate::sensors`), the Monte Carlo draws and the link's faults come from it, so a
//! run depends only on its seeds.

/// PCG32 (O'Neill 2014, "PCG: A family of simple fast space-efficient statistically good
/// algorithms for random number generation", the `pcg32` XSH-RR 64/32 generator of
/// pcg-random.org): 64-bit LCG state, 32-bit output by xorshift-high and random rotation.
/// Independent streams come from different (odd) increments.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Pcg32 {
    state: u64,
    inc: u64,
    /// The second Box–Muller deviate, kept for the next call of [`Pcg32::normal`].
    spare: Option<u64>,
}

impl Pcg32 {
    const MULTIPLIER: u64 = 6_364_136_223_846_793_005;

    /// `pcg32_srandom(seed, stream)` of the reference implementation.
    pub fn new(seed: u64, stream: u64) -> Self {
        let mut rng = Self {
            state: 0,
            inc: (stream << 1) | 1,
            spare: None,
        };
        rng.next_u32();
        rng.state = rng.state.wrapping_add(seed);
        rng.next_u32();
        rng
    }

    /// The next 32 uniformly distributed bits.
    pub fn next_u32(&mut self) -> u32 {
        let old = self.state;
        self.state = old.wrapping_mul(Self::MULTIPLIER).wrapping_add(self.inc);
        let xorshifted = (((old >> 18) ^ old) >> 27) as u32;
        let rot = (old >> 59) as u32;
        xorshifted.rotate_right(rot)
    }

    /// Uniform in (0, 1), 53 random bits (never exactly 0, so its logarithm is finite).
    pub fn uniform_open(&mut self) -> f64 {
        let bits = (u64::from(self.next_u32()) << 21) ^ u64::from(self.next_u32() >> 11);
        (bits as f64 + 0.5) / (1u64 << 53) as f64
    }

    /// A standard normal deviate (Box–Muller; the pair's second value is returned next call).
    pub fn normal(&mut self) -> f64 {
        if let Some(bits) = self.spare.take() {
            return f64::from_bits(bits);
        }
        let r = (-2.0 * self.uniform_open().ln()).sqrt();
        let phi = 2.0 * std::f64::consts::PI * self.uniform_open();
        self.spare = Some((r * phi.sin()).to_bits());
        r * phi.cos()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn pcg32_matches_the_reference_implementation() {
        // pcg32-demo of pcg-random.org: pcg32_srandom(42, 54), first six outputs.
        let mut rng = Pcg32::new(42, 54);
        let got: Vec<u32> = (0..6).map(|_| rng.next_u32()).collect();
        assert_eq!(
            got,
            [0xa15c02b7, 0x7b47f409, 0xba1d3330, 0x83d2f293, 0xbfa4784b, 0xcbed606e]
        );
    }

    #[test]
    fn normal_deviates_have_unit_variance_and_are_reproducible() {
        let mut a = Pcg32::new(7, 2);
        let n = 200_000;
        let xs: Vec<f64> = (0..n).map(|_| a.normal()).collect();
        let mean = xs.iter().sum::<f64>() / n as f64;
        let var = xs.iter().map(|x| (x - mean).powi(2)).sum::<f64>() / n as f64;
        // 5σ bounds of the sample mean and variance.
        assert!(mean.abs() < 5.0 / (n as f64).sqrt(), "{mean}");
        assert!((var - 1.0).abs() < 5.0 * (2.0 / n as f64).sqrt(), "{var}");
        let mut b = Pcg32::new(7, 2);
        assert!(xs.iter().take(100).all(|&x| x == b.normal()));
        let mut c = Pcg32::new(7, 3);
        assert_ne!(xs[0], c.normal());
    }
}
