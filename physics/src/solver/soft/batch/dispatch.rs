//! Which SIMD path solves the batches (AVX-512, AVX2 or portable), and the dispatch of
//! a batch's warm start and solve to it.

#[cfg(target_arch = "x86_64")]
use super::super::avx2::{BothHalves, LowerHalf};
#[cfg(target_arch = "x86_64")]
use super::super::avx512::F64x8Avx512;
use super::super::bodies::SoftBody;
use super::super::lanes::{F64x8, Lanes};

/// The lanes a batch is solved with: the widest this processor has.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(in crate::solver::soft) enum LanePath {
    /// `F64x8`: plain arrays, any processor.
    Portable,
    /// `Avx2Lanes`: four lanes to a 256-bit register, a row in two.
    #[cfg(target_arch = "x86_64")]
    Avx2,
    /// `F64x8Avx512`: one 512-bit register.
    #[cfg(target_arch = "x86_64")]
    Avx512,
}
impl LanePath {
    /// The fewest manifolds worth a batch of their own at the end of a colour, the other
    /// lanes unused: a batch's pass costs about three manifolds' alone in AVX-512 (one
    /// register a lane row) and in AVX2 (whose pass skips an unused upper half; two or
    /// three made the same instructions on the 20-row pyramid and the smash), six in the
    /// portable lanes.
    pub(super) fn fewest_padded(self) -> usize {
        match self {
            #[cfg(target_arch = "x86_64")]
            Self::Avx512 | Self::Avx2 => 3,
            Self::Portable => 6,
        }
    }

    /// The widest path this processor runs (detected once, then a cached flag).
    #[inline(always)]
    pub(in crate::solver::soft) fn best() -> Self {
        #[cfg(target_arch = "x86_64")]
        {
            if std::arch::is_x86_feature_detected!("avx512f") {
                return Self::Avx512;
            }
            if Self::has_avx2_and_fma() {
                return Self::Avx2;
            }
        }
        Self::Portable
    }

    /// The AVX2 path's fused multiply–adds (`Lanes::mul_add`) are FMA's instructions, which
    /// every AVX2 processor from Intel and AMD has.
    #[cfg(target_arch = "x86_64")]
    #[inline(always)]
    fn has_avx2_and_fma() -> bool {
        std::arch::is_x86_feature_detected!("avx2") && Self::has_fma()
    }

    /// Whether the processor fuses a multiply and an add in one instruction.
    #[cfg(target_arch = "x86_64")]
    #[inline(always)]
    pub(in crate::solver::soft) fn has_fma() -> bool {
        std::arch::is_x86_feature_detected!("fma")
    }

    /// Every path this processor runs, the portable one first.
    #[cfg(test)]
    pub(in crate::solver::soft) fn available() -> Vec<Self> {
        let mut paths = vec![Self::Portable];
        #[cfg(target_arch = "x86_64")]
        {
            if Self::has_avx2_and_fma() {
                paths.push(Self::Avx2);
            }
            if std::arch::is_x86_feature_detected!("avx512f") {
                paths.push(Self::Avx512);
            }
        }
        paths
    }
}

/// A batch of eight lanes stored with `F64x8` (`ManifoldBatch`, `pins::PinBatch`), whose
/// warm start and pass run with the lanes `LanePath` picks: one code, compiled for each
/// path, reading the batch's bytes as that path's lane type.
///
/// # Safety
/// `Self::With<L>` must be `Self` with `L` in place of `F64x8`: the same size, alignment
/// and layout (`repr(C)`, lanes of one size and alignment; any bits are valid in each), so
/// that a batch can be read as it.
pub(in crate::solver::soft) unsafe trait LaneBatch: Sized {
    /// What a pass reads besides the bodies.
    type Pass;
    /// The batch read with the lanes `L`.
    type With<L: Lanes>: BatchLanes<Self::Pass>;

    /// Whether any of lanes 4–7 is in use: the AVX2 path skips that half if not.
    fn upper_half_used(&self) -> bool;

    /// The warm start on every lane, with the lanes of `path`, which this processor must
    /// run (`LanePath::best`).
    fn warm_start_on(&self, path: LanePath, bodies: &mut [SoftBody]) {
        match path {
            // SAFETY: plain arrays run anywhere.
            LanePath::Portable => unsafe { as_lanes::<Self, F64x8>(self) }.warm_start_lanes(bodies),
            // SAFETY: `path` is one this processor runs (`LanePath::best`, `available`).
            #[cfg(target_arch = "x86_64")]
            LanePath::Avx2 => unsafe { warm_start_avx2(self, bodies) },
            #[cfg(target_arch = "x86_64")]
            LanePath::Avx512 => unsafe { warm_start_avx512(self, bodies) },
        }
    }

    /// A pass on every lane, with the lanes of `path`, as `warm_start_on`.
    fn solve_on(&mut self, path: LanePath, bodies: &mut [SoftBody], pass: &Self::Pass) {
        match path {
            // SAFETY: as in `warm_start_on`.
            LanePath::Portable => {
                unsafe { as_lanes_mut::<Self, F64x8>(self) }.solve_lanes(bodies, pass)
            }
            #[cfg(target_arch = "x86_64")]
            LanePath::Avx2 => unsafe { solve_avx2(self, bodies, pass) },
            #[cfg(target_arch = "x86_64")]
            LanePath::Avx512 => unsafe { solve_avx512(self, bodies, pass) },
        }
    }
}

/// A batch's warm start and pass, in the lanes it is read with (`LaneBatch::With`).
pub(in crate::solver::soft) trait BatchLanes<Pass> {
    fn warm_start_lanes(&self, bodies: &mut [SoftBody]);
    fn solve_lanes(&mut self, bodies: &mut [SoftBody], pass: &Pass);
}

/// `batch` read with the lane type `L`.
///
/// # Safety
/// The processor must run `L`'s instructions.
#[inline(always)]
unsafe fn as_lanes<B: LaneBatch, L: Lanes>(batch: &B) -> &B::With<L> {
    // SAFETY: the same bytes (`LaneBatch`'s contract); the borrow is `batch`'s.
    unsafe { &*(batch as *const B).cast::<B::With<L>>() }
}

/// # Safety
/// As `as_lanes`.
#[inline(always)]
unsafe fn as_lanes_mut<B: LaneBatch, L: Lanes>(batch: &mut B) -> &mut B::With<L> {
    // SAFETY: as `as_lanes`.
    unsafe { &mut *(batch as *mut B).cast::<B::With<L>>() }
}

/// The same code compiled for AVX2, whose 256-bit registers hold half the lanes: both
/// halves at once, interleaved, unless the upper one is unused; see `avx2`.
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2,fma")]
fn warm_start_avx2<B: LaneBatch>(batch: &B, bodies: &mut [SoftBody]) {
    // SAFETY (both): this function runs only where the processor has AVX2 and FMA
    // (`LaneBatch::warm_start_on`).
    if batch.upper_half_used() {
        unsafe { as_lanes::<B, BothHalves>(batch) }.warm_start_lanes(bodies);
    } else {
        unsafe { as_lanes::<B, LowerHalf>(batch) }.warm_start_lanes(bodies);
    }
}

/// A pass solves both halves at once, interleaved, unless the upper one is unused.
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2,fma")]
fn solve_avx2<B: LaneBatch>(batch: &mut B, bodies: &mut [SoftBody], pass: &B::Pass) {
    // SAFETY (both): this function runs only where the processor has AVX2 and FMA
    // (`LaneBatch::solve_on`).
    if batch.upper_half_used() {
        unsafe { as_lanes_mut::<B, BothHalves>(batch) }.solve_lanes(bodies, pass);
    } else {
        unsafe { as_lanes_mut::<B, LowerHalf>(batch) }.solve_lanes(bodies, pass);
    }
}

/// The same code compiled for AVX-512, whose 512-bit registers hold all eight lanes.
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx512f")]
fn warm_start_avx512<B: LaneBatch>(batch: &B, bodies: &mut [SoftBody]) {
    // SAFETY: this function runs only where the processor has AVX-512F.
    unsafe { as_lanes::<B, F64x8Avx512>(batch) }.warm_start_lanes(bodies)
}

#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx512f")]
fn solve_avx512<B: LaneBatch>(batch: &mut B, bodies: &mut [SoftBody], pass: &B::Pass) {
    // SAFETY: this function runs only where the processor has AVX-512F.
    unsafe { as_lanes_mut::<B, F64x8Avx512>(batch) }.solve_lanes(bodies, pass)
}
