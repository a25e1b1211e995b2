//! glibc's `rand()`, bit for bit: the generator DicePhys draws its throws from.
//!
//! glibc's default `random()` state is TYPE_3: an additive lagged-Fibonacci generator
//! `r[i] = r[i−3] + r[i−31] (mod 2³²)`, seeded by the Park–Miller LCG `r[i] = 16807·r[i−1]
//! mod (2³¹ − 1)`, with the first 310 outputs thrown away; each output is `r[i] >> 1`.

/// glibc's `RAND_MAX`, the largest value `rand()` returns (2³¹ − 1).
pub const RAND_MAX: i32 = 2_147_483_647;

/// glibc's `rand()` generator (TYPE_3), with its own state in place of the C library's global one.
#[derive(Clone, Debug)]
pub struct GlibcRand {
    r: [u32; 34],
    i: usize,
}

impl GlibcRand {
    /// The state after `srand(seed)`.
    pub fn new(seed: u32) -> GlibcRand {
        let seed = if seed == 0 { 1 } else { seed };
        let mut r = [0i64; 344];
        // glibc keeps the seed as an int32: a seed above 2³¹ − 1 starts the LCG negative.
        let mut word = seed as i32 as i64;
        r[0] = word;
        for slot in r.iter_mut().take(31).skip(1) {
            // 16807 * word % 2147483647 without overflow (Schrage), as glibc computes it.
            let hi = word / 127_773;
            let lo = word % 127_773;
            word = 16_807 * lo - 2_836 * hi;
            if word < 0 {
                word += 2_147_483_647;
            }
            *slot = word;
        }
        for i in 31..34 {
            r[i] = r[i - 31];
        }
        for i in 34..344 {
            r[i] = (r[i - 31] as u32).wrapping_add(r[i - 3] as u32) as i64;
        }
        let mut ring = [0u32; 34];
        for (k, slot) in ring.iter_mut().enumerate() {
            *slot = r[344 - 34 + k] as u32;
        }
        GlibcRand { r: ring, i: 0 }
    }

    /// The next `rand()`, in [0, RAND_MAX].
    pub fn next_rand(&mut self) -> i32 {
        // ring holds the last 34 values; slot i is the oldest (r[n-34]).
        let n31 = self.r[(self.i + 3) % 34]; // r[n-31]
        let n3 = self.r[(self.i + 31) % 34]; // r[n-3]
        let v = n31.wrapping_add(n3);
        self.r[self.i] = v;
        self.i = (self.i + 1) % 34;
        (v >> 1) as i32
    }

    /// DicePhys's `myRandom(from, to)`: `range * rand() / RAND_MAX + from`, evaluated in the
    /// same order so that the doubles agree to the bit.
    pub fn uniform(&mut self, from: f64, to: f64) -> f64 {
        let (from, to) = if to < from { (to, from) } else { (from, to) };
        let range = to - from;
        range * self.next_rand() as f64 / RAND_MAX as f64 + from
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    extern "C" {
        fn srand(seed: u32);
        fn rand() -> i32;
    }

    #[test]
    fn matches_the_c_library() {
        // The test binary links glibc: compare with the real thing. srand/rand share global
        // state, so this is the only test that touches them.
        for seed in [0u32, 1, 2385, 123_456_789, u32::MAX] {
            let mut g = GlibcRand::new(seed);
            let ours: Vec<i32> = (0..1000).map(|_| g.next_rand()).collect();
            let theirs: Vec<i32> = unsafe {
                srand(seed);
                (0..1000).map(|_| rand()).collect()
            };
            assert_eq!(ours, theirs, "seed {seed}");
        }
    }

    #[test]
    fn known_first_values_for_seed_1() {
        // glibc's well-known first outputs after srand(1).
        let mut g = GlibcRand::new(1);
        assert_eq!(g.next_rand(), 1_804_289_383);
        assert_eq!(g.next_rand(), 846_930_886);
        assert_eq!(g.next_rand(), 1_681_692_777);
    }
}
