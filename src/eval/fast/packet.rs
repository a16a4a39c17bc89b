//! Batches evaluated in packets: the queries are sorted along a Morton curve and cut into
//! packets of [`PACKET`] neighbours, and each packet walks the query tree once
//! ([`Hierarchy::eval_packet`](super::barnes_hut::Hierarchy)), with one lane per query.
//!
//! Why: a single query pays, per node, for loading the node (anchor, offsets, sizes and about
//! twenty far-field coefficients per lane), for the stack and for a branch per lane, and uses
//! four `f32` lanes of which some are masked out. Neighbouring queries open nearly the same
//! nodes, so a packet loads each node once for eight queries and evaluates one lane's expansion
//! for all of them in one eight-lane pass: [`Avx8`], one AVX register, on CPUs with AVX2
//! (chosen at run time, like the exact loops), else [`Lanes8`], `wide::f32x8`, which is two SSE
//! registers in a portable build (`wide` fixes its representation when it is compiled, so a
//! function compiled for AVX2 still gets the SSE pairs: measured on an AMD EPYC, 1.47–1.81× less
//! time per batch with one AVX register; plain arrays left to the auto-vectorizer came out
//! slower, split into scalar and SSE code).
//!
//! Why the values do not change: each query keeps its own admissibility mask, so it expands and
//! opens exactly the nodes it would alone; its far-field terms are the same `f32` operations
//! lane by lane (see [`Lanes8`]); and they are added to the same accumulators in the same
//! order, because the packet's depth-first walk, restricted to the entries holding one query,
//! is that query's own walk (a stack restricted to a fixed subset of its entries is still a
//! stack). So a batch equals the points evaluated one by one, bit for bit, whatever the packets,
//! the sort or the number of threads (tested).

use crate::base::bounding_box::BoundingBox;
use rayon::prelude::*;
use rdst::RadixSort;
use wide::{CmpGt, CmpLt, f32x8};

/// Queries per packet.
pub(crate) const PACKET: usize = 8;

/// Eight `f32` lanes, one per query of a packet: what the packet walk needs of them. Every
/// operation is one IEEE `f32` operation per lane (no fused multiply–add), so every
/// implementation gives every lane the bits `f32x4` gives it.
///
/// `Token` proves that the implementation can run: `()` for the portable one, and for [`Avx8`]
/// an [`Avx2`] that only exists once the CPU was found to have AVX2.
pub(crate) trait EightLanes:
    super::moments::Lanes + std::ops::Sub<Output = Self> + std::ops::Div<Output = Self>
{
    type Token: Copy;
    fn splat(token: Self::Token, v: f32) -> Self;
    fn from_array(token: Self::Token, v: [f32; PACKET]) -> Self;
    /// `(a − v[i]) as f32` per lane: the difference in `f64`, rounded once to `f32`.
    #[inline(always)]
    fn difference(token: Self::Token, a: f64, v: &[f64; PACKET]) -> Self {
        Self::from_array(token, v.map(|x| (a - x) as f32))
    }
    fn to_array(self) -> [f32; PACKET];
    fn sqrt(self) -> Self;
    /// Bit `i` set where lane `i` is `> 0` and (`bs < 0` or `> bs²`): the admissibility test.
    fn admissible(self, bs: f32) -> u32;
    /// Eight `f64` sums, one per query of a packet (the far-field sums: kept in registers).
    type Sums: Copy;
    fn zero_sums(token: Self::Token) -> Self::Sums;
    /// `sums[i] += f64::from(self[i])` where bit `i` of `bits` is set, `+= 0.0` elsewhere,
    /// which leaves the sum as it was: a sum that starts at `+0.0` is never `−0.0` in
    /// round-to-nearest, and `x + 0.0 = x` for every other `x`.
    fn add_where(self, sums: Self::Sums, bits: u32) -> Self::Sums;
    fn sums_to_array(sums: Self::Sums) -> [f64; PACKET];
    fn sums_from_array(token: Self::Token, sums: [f64; PACKET]) -> Self::Sums;
}

/// The portable eight lanes, `wide::f32x8` (one AVX register where the build targets AVX, two
/// SSE registers otherwise).
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct Lanes8(pub f32x8);

impl EightLanes for Lanes8 {
    type Token = ();

    #[inline(always)]
    fn splat((): (), v: f32) -> Self {
        Lanes8(f32x8::splat(v))
    }

    #[inline(always)]
    fn from_array((): (), v: [f32; PACKET]) -> Self {
        Lanes8(f32x8::from(v))
    }

    #[inline(always)]
    fn to_array(self) -> [f32; PACKET] {
        self.0.to_array()
    }

    #[inline(always)]
    fn sqrt(self) -> Self {
        Lanes8(self.0.sqrt())
    }

    #[inline(always)]
    fn admissible(self, bs: f32) -> u32 {
        let (zero, bs) = (f32x8::ZERO, f32x8::splat(bs));
        let admit = self.0.cmp_gt(zero) & (bs.cmp_lt(zero) | self.0.cmp_gt(bs * bs));
        admit.move_mask() as u32
    }

    type Sums = [f64; PACKET];

    #[inline(always)]
    fn zero_sums((): ()) -> [f64; PACKET] {
        [0.0; PACKET]
    }

    #[inline(always)]
    fn add_where(self, mut sums: [f64; PACKET], bits: u32) -> [f64; PACKET] {
        for (i, (s, w)) in sums.iter_mut().zip(self.to_array()).enumerate() {
            *s += if bits & (1 << i) != 0 {
                f64::from(w)
            } else {
                0.0
            };
        }
        sums
    }

    #[inline(always)]
    fn sums_to_array(sums: [f64; PACKET]) -> [f64; PACKET] {
        sums
    }

    #[inline(always)]
    fn sums_from_array((): (), sums: [f64; PACKET]) -> [f64; PACKET] {
        sums
    }
}

macro_rules! lanes8_op {
    ($trait:ident, $method:ident, $op:tt) => {
        impl std::ops::$trait for Lanes8 {
            type Output = Lanes8;
            #[inline(always)]
            fn $method(self, other: Lanes8) -> Lanes8 {
                Lanes8(self.0 $op other.0)
            }
        }
    };
}
lanes8_op!(Add, add, +);
lanes8_op!(Sub, sub, -);
lanes8_op!(Mul, mul, *);
lanes8_op!(Div, div, /);

#[cfg(target_arch = "x86_64")]
pub(crate) use avx::{Avx2, Avx8};

/// Eight lanes in one AVX register, for CPUs with AVX2 in a portable build.
///
/// Why `unsafe` here (the only place in the fast evaluator besides the run-time dispatch): the
/// AVX intrinsics may only run on a CPU that has AVX, and the methods of an operator trait
/// cannot carry `#[target_feature]`, so each call is an `unsafe` block. It is sound because
/// every `Avx8` is made from an [`Avx2`] token (or from another `Avx8`), and an `Avx2` exists
/// only after `is_x86_feature_detected!("avx2")` returned true. Inlined into the packet walk
/// compiled for AVX2 (`Hierarchy::eval_packet_avx2`), the intrinsics become single instructions.
/// The benchmark that justifies it is in the module docs.
#[cfg(target_arch = "x86_64")]
#[allow(unsafe_code)]
mod avx {
    use super::{EightLanes, PACKET};
    use std::arch::x86_64::{
        __m256, __m256d, _CMP_GT_OQ, _CMP_LT_OQ, _mm256_add_pd, _mm256_add_ps, _mm256_and_ps,
        _mm256_and_si256, _mm256_castps256_ps128, _mm256_castsi256_ps, _mm256_cmp_ps,
        _mm256_cmpeq_epi32, _mm256_cvtpd_ps, _mm256_cvtps_pd, _mm256_div_ps, _mm256_extractf128_ps,
        _mm256_loadu_pd, _mm256_loadu_ps, _mm256_movemask_ps, _mm256_mul_ps, _mm256_or_ps,
        _mm256_set_m128, _mm256_set1_epi32, _mm256_set1_pd, _mm256_set1_ps, _mm256_setr_epi32,
        _mm256_setzero_pd, _mm256_setzero_ps, _mm256_sqrt_ps, _mm256_storeu_pd, _mm256_storeu_ps,
        _mm256_sub_pd, _mm256_sub_ps,
    };

    /// Proof that the CPU has AVX2 (and so AVX): made only by [`Avx2::detect`].
    #[derive(Clone, Copy, Debug)]
    pub(crate) struct Avx2(());

    impl Avx2 {
        /// The token, when the CPU has AVX2.
        #[inline]
        pub(crate) fn detect() -> Option<Avx2> {
            std::arch::is_x86_feature_detected!("avx2").then_some(Avx2(()))
        }
    }

    #[derive(Clone, Copy, Debug)]
    pub(crate) struct Avx8(__m256);

    macro_rules! avx8_op {
        ($trait:ident, $method:ident, $intrinsic:ident) => {
            impl std::ops::$trait for Avx8 {
                type Output = Avx8;
                #[inline(always)]
                fn $method(self, other: Avx8) -> Avx8 {
                    // SAFETY: `self` exists, so the CPU has AVX (module docs).
                    Avx8(unsafe { $intrinsic(self.0, other.0) })
                }
            }
        };
    }
    avx8_op!(Add, add, _mm256_add_ps);
    avx8_op!(Sub, sub, _mm256_sub_ps);
    avx8_op!(Mul, mul, _mm256_mul_ps);
    avx8_op!(Div, div, _mm256_div_ps);

    impl EightLanes for Avx8 {
        type Token = Avx2;

        #[inline(always)]
        fn splat(_: Avx2, v: f32) -> Self {
            // SAFETY: the token proves AVX2.
            Avx8(unsafe { _mm256_set1_ps(v) })
        }

        #[inline(always)]
        fn from_array(_: Avx2, v: [f32; PACKET]) -> Self {
            // SAFETY: the token proves AVX2; the load reads the eight `f32` of `v`.
            Avx8(unsafe { _mm256_loadu_ps(v.as_ptr()) })
        }

        /// In registers: eight `f32` written one by one and loaded as one 256-bit vector stall
        /// the load (no store forwarding across the parts), which cost up to 25 % on meshes
        /// where the walk is short. `cvtpd_ps` rounds to nearest, as `as f32` does.
        #[inline(always)]
        fn difference(_: Avx2, a: f64, v: &[f64; PACKET]) -> Self {
            // SAFETY: the token proves AVX2; the loads read the eight `f64` of `v`.
            unsafe {
                let a = _mm256_set1_pd(a);
                let lo = _mm256_cvtpd_ps(_mm256_sub_pd(a, _mm256_loadu_pd(v.as_ptr())));
                let hi = _mm256_cvtpd_ps(_mm256_sub_pd(a, _mm256_loadu_pd(v.as_ptr().add(4))));
                Avx8(_mm256_set_m128(hi, lo))
            }
        }

        #[inline(always)]
        fn to_array(self) -> [f32; PACKET] {
            let mut out = [0.0f32; PACKET];
            // SAFETY: `self` proves AVX; the store writes the eight `f32` of `out`.
            unsafe { _mm256_storeu_ps(out.as_mut_ptr(), self.0) };
            out
        }

        #[inline(always)]
        fn sqrt(self) -> Self {
            // SAFETY: `self` proves AVX.
            Avx8(unsafe { _mm256_sqrt_ps(self.0) })
        }

        #[inline(always)]
        fn admissible(self, bs: f32) -> u32 {
            // SAFETY: `self` proves AVX. Ordered compares, false on NaN, as `wide`'s.
            unsafe {
                let (zero, bs) = (_mm256_setzero_ps(), _mm256_set1_ps(bs));
                let bs2 = _mm256_mul_ps(bs, bs);
                let far = _mm256_or_ps(
                    _mm256_cmp_ps::<_CMP_LT_OQ>(bs, zero),
                    _mm256_cmp_ps::<_CMP_GT_OQ>(self.0, bs2),
                );
                let admit = _mm256_and_ps(_mm256_cmp_ps::<_CMP_GT_OQ>(self.0, zero), far);
                _mm256_movemask_ps(admit) as u32
            }
        }

        /// Two `f64x4` registers (queries 0–3, 4–7).
        type Sums = (__m256d, __m256d);

        #[inline(always)]
        fn zero_sums(_: Avx2) -> Self::Sums {
            // SAFETY: the token proves AVX2.
            unsafe { (_mm256_setzero_pd(), _mm256_setzero_pd()) }
        }

        /// The bits become a lane mask (lane `i` all ones where bit `i` is set) that zeroes the
        /// other lanes in `f32` (`+0.0`, which converts to `+0.0`), then both halves are widened
        /// and added: what the portable `Lanes8` adds, lane by lane.
        #[inline(always)]
        fn add_where(self, sums: Self::Sums, bits: u32) -> Self::Sums {
            // SAFETY: `self` proves AVX2.
            unsafe {
                let bit = _mm256_setr_epi32(1, 2, 4, 8, 16, 32, 64, 128);
                let set =
                    _mm256_cmpeq_epi32(_mm256_and_si256(_mm256_set1_epi32(bits as i32), bit), bit);
                let w = _mm256_and_ps(self.0, _mm256_castsi256_ps(set));
                let lo = _mm256_cvtps_pd(_mm256_castps256_ps128(w));
                let hi = _mm256_cvtps_pd(_mm256_extractf128_ps::<1>(w));
                (_mm256_add_pd(sums.0, lo), _mm256_add_pd(sums.1, hi))
            }
        }

        #[inline(always)]
        fn sums_to_array(sums: Self::Sums) -> [f64; PACKET] {
            let mut out = [0.0; PACKET];
            // SAFETY: the sums exist, so the CPU has AVX; the stores write the eight `f64` of
            // `out`.
            unsafe {
                _mm256_storeu_pd(out.as_mut_ptr(), sums.0);
                _mm256_storeu_pd(out.as_mut_ptr().add(4), sums.1);
            }
            out
        }

        #[inline(always)]
        fn sums_from_array(_: Avx2, sums: [f64; PACKET]) -> Self::Sums {
            // SAFETY: the token proves AVX2; the loads read the eight `f64` of `sums`.
            unsafe {
                (
                    _mm256_loadu_pd(sums.as_ptr()),
                    _mm256_loadu_pd(sums.as_ptr().add(4)),
                )
            }
        }
    }

    impl super::super::moments::Lanes for Avx8 {
        #[inline(always)]
        fn rsqrt(self) -> Self {
            // SAFETY: `self` proves AVX.
            let one = Avx8(unsafe { _mm256_set1_ps(1.0) });
            one / self.sqrt()
        }
    }
}

/// Asks the CPU to bring every cache line of `value` towards the first-level cache, without
/// waiting for it (no-op off x86-64).
#[inline(always)]
pub(crate) fn prefetch<T>(value: &T) {
    #[cfg(target_arch = "x86_64")]
    {
        use std::arch::x86_64::{_MM_HINT_T0, _mm_prefetch};
        const LINE: usize = 64;
        let start = std::ptr::from_ref(value).cast::<i8>();
        for offset in (0..std::mem::size_of::<T>()).step_by(LINE) {
            // SAFETY: a prefetch is a hint: it reads nothing into the program and never faults,
            // whatever the address; every address here is inside `value` anyway. (SSE, which
            // every x86-64 CPU has.) Why it is here: docs/benchmarks.md, "near leaves listed".
            #[allow(unsafe_code)]
            unsafe {
                _mm_prefetch::<_MM_HINT_T0>(start.wrapping_add(offset));
            }
        }
    }
    #[cfg(not(target_arch = "x86_64"))]
    let _ = value;
}

/// Evaluates `points` packet by packet on rayon and returns the values in input order.
///
/// `eval_packet(points, active)` evaluates one packet: `active` has bit `i` set for the real
/// queries (a last, short packet repeats its last point in the unused lanes). The packets are
/// Morton-ordered neighbours when `in_morton_order`, else consecutive points (for a tree of one
/// node, which every query visits whatever its neighbours: the keys and the sort were a third
/// of the time of a batch on one triangle).
pub(crate) fn eval_in_packets(
    points: &[[f64; 3]],
    in_morton_order: bool,
    eval_packet: impl Fn(&[[f64; 3]; PACKET], u32) -> [f64; PACKET] + Sync,
) -> Vec<f64> {
    let order = in_morton_order.then(|| morton_order(points));
    let mut packed = vec![0.0; points.len()];
    packed
        .par_chunks_mut(PACKET)
        .enumerate()
        .with_max_len(PACKETS_PER_TASK)
        .for_each(|(p, out)| {
            let start = p * PACKET;
            let id = |i: usize| {
                let i = start + i.min(out.len() - 1);
                order.as_ref().map_or(i, |order| order[i] as usize)
            };
            let packet: [[f64; 3]; PACKET] = std::array::from_fn(|i| points[id(i)]);
            let active = (1u32 << out.len()) - 1;
            let values = eval_packet(&packet, active);
            out.copy_from_slice(&values[..out.len()]);
        });
    let Some(order) = order else {
        return packed;
    };
    let mut values = vec![0.0; points.len()];
    for (&id, &v) in order.iter().zip(&packed) {
        values[id as usize] = v;
    }
    values
}

/// Most packets one rayon task evaluates. Rayon's adaptive split leaves a few long ranges that
/// cannot be split once started: where the cost is concentrated in one part of the space (a
/// grid around a thin part), one thread idled for a fifth of a 2-thread batch (2-thread
/// scaling 1.6× on a grid, 1.9× on uniform points; docs/benchmarks.md, "Two threads").
/// Sixteen packets are tens of microseconds of work or more, against ~1 µs per task.
const PACKETS_PER_TASK: usize = 16;

/// Fewest keys [`morton_order`] sorts in parallel.
const PARALLEL_SORT: usize = 1 << 18;

/// Points per rayon task of [`morton_keys`]: a few microseconds of work.
const KEYS_PER_TASK: usize = 4096;

/// Bits per axis of the Morton code: 33 in all, of which the key keeps the top 32.
const MORTON_BITS: u32 = 11;

/// A point's place in the packets' order: the top 32 bits of its Morton code (11 bits per
/// axis: the packets need neighbours, not an exact order), which is all the sort looks at, and
/// its index.
#[derive(Clone, Copy, Debug, Default)]
struct MortonKey {
    code: u32,
    index: u32,
}

impl rdst::RadixKey for MortonKey {
    // Four byte passes, not the eight a `u64` of code and index needed: ties may come out in
    // any order, which changes no value (a query's value does not depend on its packet; see
    // the module's comment), and the sort took half of the keys-and-sort time that did not
    // scale with threads (docs/benchmarks.md, "Two threads on armadillo").
    const LEVELS: usize = 4;

    #[inline]
    fn get_level(&self, level: usize) -> u8 {
        (self.code >> (8 * level)) as u8
    }
}

/// The point indices sorted by the Morton code of their position in the box of the finite
/// points (non-finite points last).
fn morton_order(points: &[[f64; 3]]) -> Vec<u32> {
    let mut keys = morton_keys(points);
    // A radix sort (rdst, which obvhs already brings): the comparison sort took a tenth of a
    // batch of 32k queries on a 10k-face mesh (docs/benchmarks.md, "Radix-sorted packets").
    // Rayon's tasks pay off only on large batches.
    if keys.len() < PARALLEL_SORT {
        keys.radix_sort_builder()
            .with_parallel(false)
            .with_single_threaded_tuner()
            .sort();
    } else {
        keys.radix_sort_unstable();
    }
    keys.into_iter().map(|k| k.index).collect()
}

/// Per point, its [`MortonKey`].
fn morton_keys(points: &[[f64; 3]]) -> Vec<MortonKey> {
    assert!(
        points.len() <= u32::MAX as usize,
        "too many points for one batch"
    );
    // With no finite point nothing below reads the bounds.
    let (lo, hi) = points
        .par_chunks(KEYS_PER_TASK)
        .filter_map(|chunk| BoundingBox::of_points(chunk.iter().filter(|p| is_finite(p))))
        .reduce_with(|a, b| a.union(&b))
        .map_or(([0.0; 3], [0.0; 3]), |b| (b.min, b.max));
    let cells = f64::from(1u32 << MORTON_BITS);
    // Per axis: cells per unit length (0 for a flat or empty axis; the extent may overflow to
    // +∞ for points near ±f64::MAX, which gives 0 too, and only a worse order).
    let scale: [f64; 3] = std::array::from_fn(|k| {
        let s = cells / (hi[k] - lo[k]);
        if s.is_finite() { s } else { 0.0 }
    });
    let mut keys = vec![MortonKey::default(); points.len()];
    keys.par_chunks_mut(KEYS_PER_TASK)
        .zip(points.par_chunks(KEYS_PER_TASK))
        .enumerate()
        .for_each(|(task, (keys, points))| {
            // Written as a loop over plain values with the bits spread by a table: the earlier
            // `par_iter().map().collect()` with array closures and shifted masks over 21 bits
            // per axis took 13 ns per point.
            let first = task * KEYS_PER_TASK;
            for (i, (key, p)) in keys.iter_mut().zip(points).enumerate() {
                let code = if is_finite(p) {
                    // `as` saturates, and NaN (0 · ∞ cannot occur: the scale is finite) maps
                    // to 0.
                    let cell = |k: usize| {
                        let cell = ((p[k] - lo[k]) * scale[k]) as usize;
                        SPREAD[cell.min(SPREAD.len() - 1)]
                    };
                    cell(0) | (cell(1) << 1) | (cell(2) << 2)
                } else {
                    u64::MAX
                };
                *key = MortonKey {
                    code: (code >> (3 * MORTON_BITS - 32)) as u32,
                    index: (first + i) as u32,
                };
            }
        });
    keys
}

fn is_finite(p: &[f64; 3]) -> bool {
    p[0].is_finite() && p[1].is_finite() && p[2].is_finite()
}

/// Per cell coordinate `v` below 2^[`MORTON_BITS`], the bits of `v` with two zero bits
/// inserted after each: one axis's share of the Morton code.
static SPREAD: [u64; 1 << MORTON_BITS] = {
    let mut table = [0; 1 << MORTON_BITS];
    let mut v = 0;
    while v < table.len() {
        let mut bit = 0;
        while bit < MORTON_BITS {
            table[v] |= ((v as u64 >> bit) & 1) << (3 * bit);
            bit += 1;
        }
        v += 1;
    }
    table
};

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn spread_interleaves_bits() {
        for v in [0usize, 1, 2, 3, 0x7ff, 0b1011, 0x555] {
            let s = SPREAD[v];
            for b in 0..MORTON_BITS {
                assert_eq!((s >> (3 * b)) & 1, (v as u64 >> b) & 1, "v {v:#x} bit {b}");
            }
            assert_eq!(s & !0x1249249249249249, 0);
        }
    }

    #[test]
    fn packets_cover_every_point_once_in_input_order() {
        let mut points: Vec<[f64; 3]> = (0..37)
            .map(|i| {
                let t = f64::from(i);
                [(t * 0.7).sin(), (t * 1.3).cos(), t * 0.01]
            })
            .collect();
        points[5] = [f64::NAN, 0.0, 0.0];
        points[9] = [f64::INFINITY, 1.0, 0.0];
        for in_morton_order in [true, false] {
            let seen = std::sync::Mutex::new(Vec::new());
            let values = eval_in_packets(&points, in_morton_order, |packet, active| {
                assert!(active != 0 && active < (1 << PACKET));
                seen.lock().unwrap().push(active.count_ones());
                // The value of a point is its own x: any mix-up shows.
                packet.map(|p| p[0])
            });
            for (p, v) in points.iter().zip(&values) {
                assert!(p[0] == *v || (p[0].is_nan() && v.is_nan()));
            }
            let seen = seen.into_inner().unwrap();
            assert_eq!(seen.iter().sum::<u32>(), 37);
            assert_eq!(seen.len(), 37usize.div_ceil(PACKET));
        }
    }

    #[test]
    fn morton_order_groups_neighbours() {
        // A 4×4×4 grid listed x-fastest: every aligned 2×2×2 block is one packet.
        let points: Vec<[f64; 3]> = (0..64)
            .map(|i| [f64::from(i % 4), f64::from(i / 4 % 4), f64::from(i / 16)])
            .collect();
        let order = morton_order(&points);
        for packet in order.chunks(PACKET) {
            let p0 = points[packet[0] as usize];
            for &i in packet {
                let p = points[i as usize];
                assert!((0..3).all(|k| (p[k] / 2.0).floor() == (p0[k] / 2.0).floor()));
            }
        }
        assert!(morton_order(&[]).is_empty());
    }

    #[test]
    fn morton_order_is_the_order_of_the_codes_on_every_sort_path() {
        // Below rdst's comparison-sort size, its one-thread radix path, and the parallel one;
        // duplicated and non-finite points give equal codes, whose indices may come in any
        // order.
        let mut rng = crate::base::splitmix::SplitMix64(7);
        for n in [100, 5_000, PARALLEL_SORT + 3] {
            let points: Vec<[f64; 3]> = (0..n)
                .map(|i| match i % 97 {
                    0 => [f64::NAN, 0.0, 1.0],
                    1 | 2 => [0.25, 0.5, 0.75],
                    _ => [rng.unit(), rng.unit(), rng.unit() * 1e-3],
                })
                .collect();
            let keys = morton_keys(&points);
            assert!(keys.iter().enumerate().all(|(i, k)| k.index as usize == i));
            let order = morton_order(&points);
            let mut seen = vec![false; n];
            for &i in &order {
                assert!(
                    !std::mem::replace(&mut seen[i as usize], true),
                    "{n}: {i} twice"
                );
            }
            assert!(seen.iter().all(|&s| s), "{n}: a point missing");
            let codes: Vec<u32> = order.iter().map(|&i| keys[i as usize].code).collect();
            assert!(codes.is_sorted(), "{n} points: codes out of order");
            assert_eq!(codes.last(), Some(&u32::MAX), "{n}: non-finite points last");
        }
    }
}
