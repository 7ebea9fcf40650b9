//! The numbers one camera sample draws: Owen-scrambled Sobol points, padded by dimension
//! sets (Burley 2020, "Practical Hash-based Owen Scrambling", JCGT 9(4)).
//!
//! Each request — one number or a pair — takes the next *dimension set* of the sample. A
//! set reads the first one or two Sobol dimensions (the (0, 2)-sequence in base 2) at the
//! sample's index, after the index is shuffled and the values scrambled by hashes of
//! (seed, pixel, set), so:
//! - over a pixel's samples 0 … 2^k − 1, every set is stratified: a pair forms a
//!   (0, k, 2)-net, one number falls once in each interval of length 2^−k — also for any
//!   aligned range `A..B` of sample indices with power-of-two length, as `--samples`
//!   splits usually are;
//! - sets are scrambled independently, so the dimensions a path uses at its bounces are
//!   uncorrelated whatever it consumed before ("padding");
//! - sample *i* of pixel *p* depends on (seed, p, i) alone: the same numbers whichever
//!   thread, pass or process takes it, so split renders merge exactly.
//!
//! A path asks for its sets in this order: pixel filter (pair), lens (pair, when there is
//! one), shutter time (one, when something moves), then per vertex: alpha tests (one
//! each, when a surface is blended), the light sample (a triple: the point on the light
//! and the light's choice, which also decides next-event roulette), the BSDF sample (a
//! triple: the direction and the lobe), Russian roulette (one). A choice and what is drawn
//! from the part chosen share a set, so together they are stratified over the whole (two
//! triangles of a quad light are sampled as evenly as one quad). A vertex draws the light's
//! set whether or not the roulette takes its light sample, so that later sets stay
//! stratified over the pixel's samples.

use glam::Vec2;

use super::sampling::mix64;

/// Where a camera sample is in its sequence.
#[derive(Clone, Debug)]
pub struct Sampler {
    /// Hash of (seed, pixel): the scrambles of this pixel's sets derive from it.
    pixel_seed: u32,
    /// The sample's index among all of the pixel's samples, bit-reversed: the form the
    /// index shuffle takes it in.
    index_reversed: u32,
    /// The next dimension set.
    set: u32,
}

impl Sampler {
    /// The sequence of sample `sample` of pixel `pixel`, for seed `seed`.
    pub fn for_sample(seed: u64, pixel: u64, sample: u32) -> Sampler {
        Sampler {
            pixel_seed: mix64(mix64(seed) ^ pixel) as u32,
            index_reversed: sample.reverse_bits(),
            set: 0,
        }
    }

    /// One number in [0, 1), stratified over the pixel's samples.
    pub fn uniform(&mut self) -> f32 {
        self.next_set().first()
    }

    /// Two numbers in [0, 1)², jointly stratified over the pixel's samples.
    pub fn uniform2(&mut self) -> Vec2 {
        let set = self.next_set();
        Vec2::new(set.first(), set.dimension(&SOBOL_SECOND_BYTES, 2))
    }

    /// Three numbers in [0, 1)³ from one set: a pair as [`Sampler::uniform2`] gives it
    /// and a third number from Sobol's third dimension, so that the three are stratified
    /// jointly (a choice among parts and a point on the part chosen fall evenly over the
    /// whole; Burley 2020 pads by four-dimensional Sobol sets).
    pub fn uniform3(&mut self) -> (Vec2, f32) {
        let set = self.next_set();
        let pair = Vec2::new(set.first(), set.dimension(&SOBOL_SECOND_BYTES, 2));
        (pair, set.dimension(&SOBOL_THIRD_BYTES, 3))
    }

    fn next_set(&mut self) -> Set {
        let seed = hash_combine(self.pixel_seed, self.set);
        self.set += 1;
        Set {
            seed,
            // nested_uniform_scramble(index, seed), bit-reversed.
            shuffled_reversed: laine_karras(self.index_reversed, seed),
        }
    }
}

/// One dimension set of a sample: its seed, and the sample's index shuffled by it, kept
/// bit-reversed. Bit reversal is a dozen instructions on x86-64, and each Owen scramble
/// works on reversed bits, so the index and the tables stay in that form and each number
/// is reversed once, at the end.
struct Set {
    seed: u32,
    shuffled_reversed: u32,
}

impl Set {
    /// The set's first dimension.
    #[inline]
    fn first(&self) -> f32 {
        to_unit(scrambled_first(
            self.shuffled_reversed.reverse_bits(),
            self.seed,
        ))
    }

    /// Dimension `dimension` (2 or 3), from its byte tables over reversed indices,
    /// Owen-scrambled: `nested_uniform_scramble(sobol(index), s)` is
    /// `laine_karras(sobol(index).reverse_bits(), s).reverse_bits()`, and the tables give
    /// `sobol(index).reverse_bits()` from the reversed index directly.
    #[inline]
    fn dimension(&self, tables: &[[u32; 256]; 4], dimension: u32) -> f32 {
        let x = sobol_by_bytes(tables, self.shuffled_reversed);
        to_unit(laine_karras(x, hash_combine(self.seed, dimension)).reverse_bits())
    }
}

/// The first Sobol dimension (the bits of `index` reversed), Owen-scrambled. Scrambling
/// reverses its input's bits, so the two reversals cancel:
/// `nested_uniform_scramble(index.reverse_bits(), s)` = `laine_karras(index, s).reverse_bits()`.
fn scrambled_first(index: u32, seed: u32) -> u32 {
    laine_karras(index, hash_combine(seed, 1)).reverse_bits()
}

/// The XOR of the direction numbers of the set bits of `x`, a byte at a time from `tables`
/// (built by [`byte_tables`]): shuffled indices have random high bits, so a loop over the
/// bits would branch unpredictably 32 times per number.
#[inline]
fn sobol_by_bytes(tables: &[[u32; 256]; 4], x: u32) -> u32 {
    tables[0][(x & 0xff) as usize]
        ^ tables[1][((x >> 8) & 0xff) as usize]
        ^ tables[2][((x >> 16) & 0xff) as usize]
        ^ tables[3][(x >> 24) as usize]
}

/// The second Sobol dimension's direction numbers: generator matrix from the primitive
/// polynomial x + 1 (v₀ = 2³¹, vᵢ = vᵢ₋₁ ⊕ (vᵢ₋₁ ≫ 1)).
const SECOND_DIRECTIONS: [u32; 32] = {
    let mut direction = [0u32; 32];
    let mut v = 1u32 << 31;
    let mut i = 0;
    while i < 32 {
        direction[i] = v;
        v ^= v >> 1;
        i += 1;
    }
    direction
};

/// The third Sobol dimension's direction numbers: generator matrix from the primitive
/// polynomial x² + x + 1 with initial numbers m = 1, 3 (Joe & Kuo 2008's table;
/// vᵢ = vᵢ₋₁ ⊕ vᵢ₋₂ ⊕ (vᵢ₋₂ ≫ 2)).
const THIRD_DIRECTIONS: [u32; 32] = {
    let mut direction = [0u32; 32];
    direction[0] = 1 << 31;
    direction[1] = 3 << 30;
    let mut i = 2;
    while i < 32 {
        direction[i] = direction[i - 1] ^ direction[i - 2] ^ (direction[i - 2] >> 2);
        i += 1;
    }
    direction
};

/// The second dimension by bytes of the reversed index, bit-reversed.
const SOBOL_SECOND_BYTES: [[u32; 256]; 4] = byte_tables(&reversed(&SECOND_DIRECTIONS));

/// The third dimension by bytes of the reversed index, bit-reversed.
const SOBOL_THIRD_BYTES: [[u32; 256]; 4] = byte_tables(&reversed(&THIRD_DIRECTIONS));

/// Direction numbers for a bit-reversed index, giving bit-reversed values: bit j of the
/// reversed index is bit 31 − j of the index.
const fn reversed(direction: &[u32; 32]) -> [u32; 32] {
    let mut out = [0u32; 32];
    let mut j = 0;
    while j < 32 {
        out[j] = direction[31 - j].reverse_bits();
        j += 1;
    }
    out
}

/// For byte `b` of an index and each value of it, the XOR of the direction numbers of its
/// set bits.
const fn byte_tables(direction: &[u32; 32]) -> [[u32; 256]; 4] {
    let mut table = [[0u32; 256]; 4];
    let mut b = 0;
    while b < 4 {
        let mut value = 0;
        while value < 256 {
            let mut x = 0;
            let mut bit = 0;
            while bit < 8 {
                if value & (1 << bit) != 0 {
                    x ^= direction[8 * b + bit];
                }
                bit += 1;
            }
            table[b][value] = x;
            value += 1;
        }
        b += 1;
    }
    table
}

/// The Laine–Karras permutation with Burley's constants: each bit of `v` flipped by a hash
/// of the bits below it.
fn laine_karras(v: u32, seed: u32) -> u32 {
    let mut v = v.wrapping_add(seed);
    v ^= v.wrapping_mul(0x6c50_b47c);
    v ^= v.wrapping_mul(0xb82f_1e52);
    v ^= v.wrapping_mul(0xc7af_e638);
    v ^= v.wrapping_mul(0x8d22_f6e6);
    v
}

/// Burley's hash_combine (after Boost): a seed for a sub-stream, from a 32-bit integer
/// hash of `v` (Wellons' "lowbias32", a bijection with low bias).
fn hash_combine(seed: u32, v: u32) -> u32 {
    let mut h = v;
    h ^= h >> 16;
    h = h.wrapping_mul(0x7feb_352d);
    h ^= h >> 15;
    h = h.wrapping_mul(0x846c_a68b);
    h ^= h >> 16;
    seed ^ (h
        .wrapping_add(0x9e37_79b9)
        .wrapping_add(seed << 6)
        .wrapping_add(seed >> 2))
}

/// The top 24 bits as a float in [0, 1).
fn to_unit(x: u32) -> f32 {
    (x >> 8) as f32 * (1.0 / (1u32 << 24) as f32)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The second dimension bit by bit, as its definition reads.
    fn sobol_second_by_bits(index: u32) -> u32 {
        let mut x = 0;
        let mut v = 1u32 << 31;
        let mut i = index;
        while i != 0 {
            if i & 1 == 1 {
                x ^= v;
            }
            i >>= 1;
            v ^= v >> 1;
        }
        x
    }

    /// Owen scrambling of the bits of `x` as a nested uniform scramble: each bit flipped by
    /// a hash of the bits above it (Burley 2020, §3: the Laine–Karras permutation on
    /// reversed bits, with Burley's improved constants).
    fn nested_uniform_scramble(x: u32, seed: u32) -> u32 {
        laine_karras(x.reverse_bits(), seed).reverse_bits()
    }

    /// The second dimension at `index` from the tables, as its definition takes it.
    fn sobol_second(index: u32) -> u32 {
        sobol_by_bytes(&SOBOL_SECOND_BYTES, index.reverse_bits()).reverse_bits()
    }

    /// The third dimension at `index` from the tables.
    fn sobol_third(index: u32) -> u32 {
        sobol_by_bytes(&SOBOL_THIRD_BYTES, index.reverse_bits()).reverse_bits()
    }

    #[test]
    fn the_byte_tables_give_the_second_dimension_bit_for_bit() {
        let mut h = 1u32;
        for i in 0..200_000u32 {
            h = h.wrapping_mul(747_796_405).wrapping_add(2_891_336_453);
            for index in [i, h, h | 0x8000_0000, u32::MAX - i] {
                assert_eq!(sobol_second(index), sobol_second_by_bits(index), "{index}");
            }
        }
    }

    /// A set as Burley's paper writes it: the index shuffled by a nested uniform scramble,
    /// each dimension's value scrambled by its own.
    fn set_by_definition(pixel_seed: u32, set: u32, index: u32) -> (f32, f32, f32) {
        let seed = hash_combine(pixel_seed, set);
        let shuffled = nested_uniform_scramble(index, seed);
        let scramble = |x: u32, d: u32| to_unit(nested_uniform_scramble(x, hash_combine(seed, d)));
        (
            scramble(shuffled.reverse_bits(), 1),
            scramble(sobol_second_by_bits(shuffled), 2),
            scramble(sobol_third(shuffled), 3),
        )
    }

    #[test]
    fn the_sets_are_the_definitions_numbers_to_the_bit() {
        for (seed, pixel) in [(0u64, 0u64), (7, 12_345), (u64::MAX, 99)] {
            for index in [0u32, 1, 2, 3, 17, 255, 256, 65_537, 1 << 31, u32::MAX] {
                let mut s = Sampler::for_sample(seed, pixel, index);
                let one = s.uniform();
                let two = s.uniform2();
                let (pair, third) = s.uniform3();
                let d = |set| set_by_definition(s.pixel_seed, set, index);
                assert_eq!(one, d(0).0);
                assert_eq!((two.x, two.y), (d(1).0, d(1).1));
                assert_eq!((pair.x, pair.y, third), d(2));
            }
        }
    }

    /// Every elementary interval of area 2^−k holds exactly one of 2^k points.
    fn is_net(points: &[Vec2], k: u32) -> bool {
        (0..=k).all(|bits_x| {
            let (nx, ny) = (1usize << bits_x, 1usize << (k - bits_x));
            let mut seen = vec![false; nx * ny];
            points.iter().all(|p| {
                let cell = (p.y * ny as f32) as usize * nx + (p.x * nx as f32) as usize;
                !std::mem::replace(&mut seen[cell], true)
            })
        })
    }

    /// Aligned power-of-two ranges of sample indices (start, log₂ length), as `--samples`
    /// splits usually are.
    const ALIGNED_RANGES: [(u32, u32); 5] = [(0, 4), (0, 8), (64, 6), (256, 8), (4096, 10)];

    /// For 20 pixels, each range and each of `sets` sets: what `draw` gives at that set over
    /// the range's samples, with the pixel, range and set it came from.
    fn each_set_over_ranges<T>(
        seed: u64,
        sets: usize,
        draw: impl Fn(&mut Sampler) -> T,
        mut check: impl FnMut(Vec<T>, u32, String),
    ) {
        for pixel in 0..20u64 {
            for (start, k) in ALIGNED_RANGES {
                for set in 0..sets {
                    let points = (start..start + (1 << k))
                        .map(|i| {
                            let mut s = Sampler::for_sample(seed, pixel, i);
                            for _ in 0..set {
                                draw(&mut s);
                            }
                            draw(&mut s)
                        })
                        .collect();
                    check(
                        points,
                        k,
                        format!("pixel {pixel}, samples {start}+2^{k}, set {set}"),
                    );
                }
            }
        }
    }

    #[test]
    fn each_pair_of_a_pixels_samples_is_a_net_for_aligned_power_of_two_ranges() {
        each_set_over_ranges(7, 6, Sampler::uniform2, |points, k, at| {
            assert!(is_net(&points, k), "{at}");
        });
    }

    /// Every elementary box of volume 2^(1−k) holds exactly two of 2^k points: Sobol's first
    /// three dimensions form (1, k, 3)-nets, the best base 2 allows in three dimensions
    /// beside the (0, 2) pair.
    fn is_three_dimensional_net(points: &[(Vec2, f32)], k: u32) -> bool {
        let m = k - 1;
        (0..=m).all(|bits_x| {
            (0..=m - bits_x).all(|bits_y| {
                let bits_z = m - bits_x - bits_y;
                let (nx, ny, nz) = (1usize << bits_x, 1usize << bits_y, 1usize << bits_z);
                let mut counts = vec![0u8; nx * ny * nz];
                for (pair, third) in points {
                    let (x, y) = ((pair.x * nx as f32) as usize, (pair.y * ny as f32) as usize);
                    let z = (third * nz as f32) as usize;
                    counts[(z * ny + y) * nx + x] += 1;
                }
                counts.iter().all(|&c| c == 2)
            })
        })
    }

    #[test]
    fn each_triple_of_a_pixels_samples_is_a_net_for_aligned_power_of_two_ranges() {
        each_set_over_ranges(5, 4, Sampler::uniform3, |points, k, at| {
            assert!(is_three_dimensional_net(&points, k), "{at}");
            let pairs: Vec<Vec2> = points.iter().map(|p| p.0).collect();
            assert!(is_net(&pairs, k), "pair of {at}");
        });
    }

    #[test]
    fn the_third_dimension_starts_as_sobols_does() {
        // Sobol's third dimension at indices 0..8 (direction numbers 1/2, 3/4, 3/8).
        let expected = [0.0, 0.5, 0.75, 0.25, 0.375, 0.875, 0.625, 0.125];
        for (i, e) in expected.iter().enumerate() {
            assert_eq!(
                sobol_third(i as u32) as f64 / 2f64.powi(32),
                *e,
                "index {i}"
            );
        }
    }

    #[test]
    fn single_numbers_fall_once_in_each_stratum() {
        for pixel in 0..50u64 {
            let mut seen = [false; 256];
            for i in 0..256 {
                let mut s = Sampler::for_sample(3, pixel, i);
                s.uniform2();
                let u = s.uniform();
                assert!(!std::mem::replace(&mut seen[(u * 256.0) as usize], true));
            }
        }
    }

    /// Pearson's χ² over `bins` equally likely bins, against the 99.99 % point of its
    /// distribution (Wilson–Hilferty).
    fn chi_square_ok(counts: &[u64]) -> (f64, f64) {
        let n: u64 = counts.iter().sum();
        let expected = n as f64 / counts.len() as f64;
        let chi: f64 = counts
            .iter()
            .map(|&c| (c as f64 - expected).powi(2) / expected)
            .sum();
        (
            chi,
            crate::render::chi_square::upper_point((counts.len() - 1) as f64),
        )
    }

    #[test]
    fn pixels_and_sets_are_independent() {
        // The same sample of many pixels is uniform, and a set is not tied to the next one:
        // (set 1's x, set 2's y) over pixels fills the square evenly.
        let bins = 16;
        let mut marginal = vec![0u64; bins];
        let mut joint = vec![0u64; bins * bins];
        for pixel in 0..200_000u64 {
            let mut s = Sampler::for_sample(11, pixel, 5);
            s.uniform2();
            let a = s.uniform2().x;
            let b = s.uniform2().y;
            marginal[(a * bins as f32) as usize] += 1;
            joint[(b * bins as f32) as usize * bins + (a * bins as f32) as usize] += 1;
        }
        for counts in [&marginal, &joint] {
            let (chi, limit) = chi_square_ok(counts);
            assert!(chi < limit, "χ² {chi:.1} over the 99.99 % point {limit:.1}");
        }
    }

    #[test]
    fn the_shortcut_for_the_first_dimension_is_the_full_scramble() {
        for (index, seed) in [(0u32, 1u32), (5, 77), (1 << 20, 0xdead_beef), (u32::MAX, 3)] {
            assert_eq!(
                scrambled_first(index, seed),
                nested_uniform_scramble(index.reverse_bits(), hash_combine(seed, 1))
            );
        }
    }

    #[test]
    fn a_sample_depends_on_seed_pixel_and_index_alone() {
        let draw = |seed, pixel, i| {
            let mut s = Sampler::for_sample(seed, pixel, i);
            (s.uniform2(), s.uniform(), s.uniform2())
        };
        assert_eq!(draw(1, 2, 3), draw(1, 2, 3));
        assert_ne!(draw(1, 2, 3), draw(2, 2, 3));
        assert_ne!(draw(1, 2, 3), draw(1, 3, 3));
    }
}
