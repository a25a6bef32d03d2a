//! Small dense kernels for the batched passes: a register-tiled matrix product, a transpose, and
//! the exact (erf) GELU with its first two derivatives over a whole layer, vectorised.
//!
//! Every output element is accumulated in the same order (k = 0, 1, …, depth−1, one fused
//! multiply-add per term) whatever the tile it falls in and whatever instruction set runs, so the
//! AVX-512, AVX2 and portable builds give bit-identical results (the portable build uses
//! `f64::mul_add`, a correctly rounded fused multiply-add, like the FMA instruction).

/// Row and column strides of a read-only operand `a` in `a[row·row_stride + k·depth_stride]`.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Strides {
    pub row: usize,
    pub depth: usize,
}

/// The instruction set the kernels run with, detected once.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum Isa {
    Portable,
    #[cfg(target_arch = "x86_64")]
    Avx2,
    #[cfg(target_arch = "x86_64")]
    Avx512,
}

fn isa() -> Isa {
    use std::sync::OnceLock;
    static DETECTED: OnceLock<Isa> = OnceLock::new();
    *DETECTED.get_or_init(|| {
        #[cfg(target_arch = "x86_64")]
        {
            if std::is_x86_feature_detected!("avx512f") && std::is_x86_feature_detected!("fma") {
                return Isa::Avx512;
            }
            if std::is_x86_feature_detected!("avx2") && std::is_x86_feature_detected!("fma") {
                return Isa::Avx2;
            }
        }
        Isa::Portable
    })
}

/// Defines `fn $name(args)` that runs its body compiled for AVX-512, AVX2 or the portable
/// baseline, as detected. For element-wise loops: no fused multiply-add is introduced, so every
/// build computes the same roundings.
macro_rules! dispatched {
    ($(#[$meta:meta])* $vis:vis fn $name:ident($($arg:ident: $ty:ty),* $(,)?) $body:block) => {
        $(#[$meta])*
        $vis fn $name($($arg: $ty),*) {
            #[inline(always)]
            fn portable($($arg: $ty),*) $body
            #[cfg(target_arch = "x86_64")]
            #[target_feature(enable = "avx512f,fma")]
            fn avx512($($arg: $ty),*) {
                portable($($arg),*)
            }
            #[cfg(target_arch = "x86_64")]
            #[target_feature(enable = "avx2,fma")]
            fn avx2($($arg: $ty),*) {
                portable($($arg),*)
            }
            match $crate::kernels::detected_isa() {
                #[cfg(target_arch = "x86_64")]
                // SAFETY: the instruction set was detected.
                $crate::kernels::Isa::Avx512 => unsafe { avx512($($arg),*) },
                #[cfg(target_arch = "x86_64")]
                // SAFETY: the instruction set was detected.
                $crate::kernels::Isa::Avx2 => unsafe { avx2($($arg),*) },
                $crate::kernels::Isa::Portable => portable($($arg),*),
            }
        }
    };
}
pub(crate) use dispatched;

/// The detected instruction set (for [`dispatched`]).
pub(crate) fn detected_isa() -> Isa {
    isa()
}

dispatched! {
    /// out[c] = Σ_b matrix[b·width + c], summed in row order. Columns go in blocks of 32, then 8,
    /// then one at a time, each block's sums held in registers over all rows (a running sum kept
    /// in `out` made every row a store-to-load round trip).
    pub(crate) fn column_sums(matrix: &[f64], width: usize, out: &mut [f64]) {
        let mut start = 0;
        while start + 32 <= width {
            column_block_sums::<32>(matrix, width, start, out);
            start += 32;
        }
        while start + 8 <= width {
            column_block_sums::<8>(matrix, width, start, out);
            start += 8;
        }
        while start < width {
            column_block_sums::<1>(matrix, width, start, out);
            start += 1;
        }
    }
}

/// out[start..start + COLUMNS] of [`column_sums`].
#[inline(always)]
fn column_block_sums<const COLUMNS: usize>(
    matrix: &[f64],
    width: usize,
    start: usize,
    out: &mut [f64],
) {
    let mut sums = [0.0; COLUMNS];
    for row in matrix.chunks_exact(width) {
        let block: &[f64; COLUMNS] = row[start..start + COLUMNS].try_into().expect("block");
        for (sum, &value) in sums.iter_mut().zip(block) {
            *sum += value;
        }
    }
    out[start..start + COLUMNS].copy_from_slice(&sums);
}

dispatched! {
    /// out[i] = a[i]·b[i].
    pub(crate) fn hadamard(out: &mut [f64], a: &[f64], b: &[f64]) {
        for ((o, &x), &y) in out.iter_mut().zip(a).zip(b) {
            *o = x * y;
        }
    }
}

dispatched! {
    /// r[i] ← r[i]·first[i] + back[i]·second[i]·r_pre[i] (the R-operator's δ through a GELU).
    pub(crate) fn r_delta_through_gelu(
        r: &mut [f64],
        first: &[f64],
        second: &[f64],
        back: &[f64],
        r_pre: &[f64],
    ) {
        for ((((r, &d1), &d2), &e), &z) in r.iter_mut().zip(first).zip(second).zip(back).zip(r_pre) {
            *r = *r * d1 + e * d2 * z;
        }
    }
}

/// out[r·ldo + c] (= or, with `accumulate`, +=) Σ_k a[r·a.row + k·a.depth] · b[k·ldb + c]
/// for r < rows, c < cols, k < depth.
#[allow(clippy::too_many_arguments)]
pub(crate) fn matmul(
    rows: usize,
    cols: usize,
    depth: usize,
    a: &[f64],
    a_strides: Strides,
    b: &[f64],
    ldb: usize,
    out: &mut [f64],
    ldo: usize,
    accumulate: bool,
) {
    matmul_with_bias(
        rows, cols, depth, a, a_strides, b, ldb, out, ldo, accumulate, None,
    );
}

/// [`matmul`] where, when `bias` is given (and `accumulate` is false), every output row starts
/// from `bias[..cols]` instead of zero.
#[allow(clippy::too_many_arguments)]
pub(crate) fn matmul_with_bias(
    rows: usize,
    cols: usize,
    depth: usize,
    a: &[f64],
    a_strides: Strides,
    b: &[f64],
    ldb: usize,
    out: &mut [f64],
    ldo: usize,
    accumulate: bool,
    bias: Option<&[f64]>,
) {
    if rows == 0 || cols == 0 {
        return;
    }
    if let Some(bias) = bias {
        assert!(bias.len() >= cols, "matmul: bias too short");
    }
    assert!(cols <= ldo && cols <= ldb.max(cols));
    assert!(
        out.len() >= (rows - 1) * ldo + cols,
        "matmul: output too short"
    );
    if depth > 0 {
        assert!(
            a.len() > (rows - 1) * a_strides.row + (depth - 1) * a_strides.depth,
            "matmul: left operand too short"
        );
        assert!(
            b.len() >= (depth - 1) * ldb + cols,
            "matmul: right operand too short"
        );
    }
    let call = MatmulCall {
        rows,
        cols,
        depth,
        a: a.as_ptr(),
        a_strides,
        b: b.as_ptr(),
        ldb,
        out: out.as_mut_ptr(),
        ldo,
        accumulate,
        bias: bias.map_or(std::ptr::null(), <[f64]>::as_ptr),
    };
    // SAFETY: the bounds of every access were checked above; the instruction set was detected.
    unsafe {
        match isa() {
            #[cfg(target_arch = "x86_64")]
            Isa::Avx512 => call.run_avx512(),
            #[cfg(target_arch = "x86_64")]
            Isa::Avx2 => call.run_avx2(),
            Isa::Portable => call.run_portable(),
        }
    }
}

/// The portable build of [`matmul`] (for the test that all builds agree bit for bit).
#[cfg(test)]
#[allow(clippy::too_many_arguments)]
fn matmul_portable(
    rows: usize,
    cols: usize,
    depth: usize,
    a: &[f64],
    a_strides: Strides,
    b: &[f64],
    ldb: usize,
    out: &mut [f64],
    ldo: usize,
    accumulate: bool,
) {
    assert!(out.len() >= (rows - 1) * ldo + cols);
    assert!(a.len() > (rows - 1) * a_strides.row + (depth - 1) * a_strides.depth);
    assert!(b.len() >= (depth - 1) * ldb + cols);
    let call = MatmulCall {
        rows,
        cols,
        depth,
        a: a.as_ptr(),
        a_strides,
        b: b.as_ptr(),
        ldb,
        out: out.as_mut_ptr(),
        ldo,
        accumulate,
        bias: std::ptr::null(),
    };
    // SAFETY: bounds checked above.
    unsafe { call.run_portable() }
}

struct MatmulCall {
    rows: usize,
    cols: usize,
    depth: usize,
    a: *const f64,
    a_strides: Strides,
    b: *const f64,
    ldb: usize,
    out: *mut f64,
    ldo: usize,
    accumulate: bool,
    /// Null, or the row every output row starts from.
    bias: *const f64,
}

impl MatmulCall {
    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx512f,fma")]
    unsafe fn run_avx512(&self) {
        // SAFETY: forwarded from `matmul`.
        unsafe { <x86::Avx512 as x86::Lanes>::run::<8>(self) }
    }

    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx2,fma")]
    unsafe fn run_avx2(&self) {
        // SAFETY: forwarded from `matmul`.
        unsafe { <x86::Avx2 as x86::Lanes>::run::<4>(self) }
    }

    unsafe fn run_portable(&self) {
        // SAFETY: forwarded from `matmul`.
        unsafe { self.run::<4, 4>() }
    }

    /// Tiles of ROWS × COLS, then narrower column tiles (8, 4, 1) and single rows at the edges.
    #[inline(always)]
    unsafe fn run<const ROWS: usize, const COLS: usize>(&self) {
        let mut row = 0;
        while row + ROWS <= self.rows {
            // SAFETY: (row..row + ROWS) lies inside the checked range.
            unsafe { self.row_block::<ROWS, COLS>(row) };
            row += ROWS;
        }
        if ROWS > 4 && row + 4 <= self.rows {
            // SAFETY: as above.
            unsafe { self.row_block::<4, COLS>(row) };
            row += 4;
        }
        if ROWS > 2 && row + 2 <= self.rows {
            // SAFETY: as above.
            unsafe { self.row_block::<2, COLS>(row) };
            row += 2;
        }
        while row < self.rows {
            // SAFETY: as above.
            unsafe { self.row_block::<1, COLS>(row) };
            row += 1;
        }
    }

    #[inline(always)]
    unsafe fn row_block<const ROWS: usize, const COLS: usize>(&self, row: usize) {
        let mut col = 0;
        while col + COLS <= self.cols {
            // SAFETY: inside the checked range.
            unsafe { self.tile::<ROWS, COLS>(row, col) };
            col += COLS;
        }
        if COLS > 8 && col + 8 <= self.cols {
            // SAFETY: inside the checked range.
            unsafe { self.tile::<ROWS, 8>(row, col) };
            col += 8;
        }
        if COLS > 4 && col + 4 <= self.cols {
            // SAFETY: inside the checked range.
            unsafe { self.tile::<ROWS, 4>(row, col) };
            col += 4;
        }
        while col < self.cols {
            // SAFETY: inside the checked range.
            unsafe { self.tile::<ROWS, 1>(row, col) };
            col += 1;
        }
    }

    #[inline(always)]
    unsafe fn tile<const ROWS: usize, const COLS: usize>(&self, row: usize, col: usize) {
        let mut accumulators = [[0.0f64; COLS]; ROWS];
        // SAFETY (whole function): every pointer stays inside the ranges checked in `matmul`.
        unsafe {
            let out = self.out.add(row * self.ldo + col);
            if self.accumulate {
                for (r, accumulator) in accumulators.iter_mut().enumerate() {
                    *accumulator = std::ptr::read_unaligned(out.add(r * self.ldo).cast());
                }
            } else if !self.bias.is_null() {
                let bias: [f64; COLS] = std::ptr::read_unaligned(self.bias.add(col).cast());
                accumulators = [bias; ROWS];
            }
            let mut a = self.a.add(row * self.a_strides.row);
            let mut b = self.b.add(col);
            for _ in 0..self.depth {
                let b_values: [f64; COLS] = std::ptr::read_unaligned(b.cast());
                for (r, accumulator) in accumulators.iter_mut().enumerate() {
                    let a_value = *a.add(r * self.a_strides.row);
                    for (sum, &b_value) in accumulator.iter_mut().zip(&b_values) {
                        *sum = a_value.mul_add(b_value, *sum);
                    }
                }
                a = a.add(self.a_strides.depth);
                b = b.add(self.ldb);
            }
            for (r, accumulator) in accumulators.iter().enumerate() {
                std::ptr::write_unaligned(out.add(r * self.ldo).cast(), *accumulator);
            }
        }
    }
}

/// Explicit SIMD tiles: ROWS × (up to 3 vectors) accumulators in registers, one broadcast of `a` per row
/// and one fused multiply-add per accumulator for each k; the last columns use masked loads and
/// stores, so every column takes the same path.
#[cfg(target_arch = "x86_64")]
mod x86 {
    use std::arch::x86_64::*;

    use super::MatmulCall;

    /// One vector width: its register type, masked load and store, broadcast and FMA.
    pub(super) trait Lanes {
        type Vector: Copy;
        type Mask: Copy;
        const WIDTH: usize;
        unsafe fn mask(count: usize) -> Self::Mask;
        unsafe fn load(pointer: *const f64, mask: Self::Mask) -> Self::Vector;
        unsafe fn store(pointer: *mut f64, value: Self::Vector, mask: Self::Mask);
        unsafe fn splat(value: f64) -> Self::Vector;
        unsafe fn zero() -> Self::Vector;
        unsafe fn fmadd(a: Self::Vector, b: Self::Vector, c: Self::Vector) -> Self::Vector;

        /// Tiles of ROWS rows (then 4, 2, 1 at the bottom edge).
        #[inline(always)]
        unsafe fn run<const ROWS: usize>(call: &MatmulCall) {
            let mut row = 0;
            // SAFETY (whole function): the tiles stay inside the ranges checked in `matmul`.
            unsafe {
                while row + ROWS <= call.rows {
                    Self::row_block::<ROWS>(call, row);
                    row += ROWS;
                }
                if ROWS > 4 && row + 4 <= call.rows {
                    Self::row_block::<4>(call, row);
                    row += 4;
                }
                if row + 2 <= call.rows {
                    Self::row_block::<2>(call, row);
                    row += 2;
                }
                if row < call.rows {
                    Self::row_block::<1>(call, row);
                }
            }
        }

        #[inline(always)]
        unsafe fn row_block<const ROWS: usize>(call: &MatmulCall, row: usize) {
            let width = Self::WIDTH;
            let mut col = 0;
            // SAFETY (whole function): as in `run`.
            unsafe {
                let full = Self::mask(width);
                while col + 3 * width <= call.cols {
                    Self::tile::<ROWS, 3>(call, row, col, [full, full, full]);
                    col += 3 * width;
                }
                let left = call.cols - col;
                if left > 2 * width {
                    let last = Self::mask(left - 2 * width);
                    Self::tile::<ROWS, 3>(call, row, col, [full, full, last]);
                } else if left > width {
                    Self::tile::<ROWS, 2>(call, row, col, [full, Self::mask(left - width)]);
                } else if left > 0 {
                    Self::tile::<ROWS, 1>(call, row, col, [Self::mask(left)]);
                }
            }
        }

        #[inline(always)]
        unsafe fn tile<const ROWS: usize, const VECTORS: usize>(
            call: &MatmulCall,
            row: usize,
            col: usize,
            masks: [Self::Mask; VECTORS],
        ) {
            let width = Self::WIDTH;
            // SAFETY (whole function): as in `run`; masked lanes are neither read nor written.
            unsafe {
                let out = call.out.add(row * call.ldo + col);
                let mut accumulators = [[Self::zero(); VECTORS]; ROWS];
                for (r, accumulator) in accumulators.iter_mut().enumerate() {
                    for (v, sum) in accumulator.iter_mut().enumerate() {
                        if call.accumulate {
                            *sum = Self::load(out.add(r * call.ldo + v * width), masks[v]);
                        } else if !call.bias.is_null() {
                            *sum = Self::load(call.bias.add(col + v * width), masks[v]);
                        }
                    }
                }
                let mut a = call.a.add(row * call.a_strides.row);
                let mut b = call.b.add(col);
                for _ in 0..call.depth {
                    let mut b_values = [Self::zero(); VECTORS];
                    for (v, value) in b_values.iter_mut().enumerate() {
                        *value = Self::load(b.add(v * width), masks[v]);
                    }
                    for (r, accumulator) in accumulators.iter_mut().enumerate() {
                        let a_value = Self::splat(*a.add(r * call.a_strides.row));
                        for (sum, &b_value) in accumulator.iter_mut().zip(&b_values) {
                            *sum = Self::fmadd(a_value, b_value, *sum);
                        }
                    }
                    a = a.add(call.a_strides.depth);
                    b = b.add(call.ldb);
                }
                for (r, accumulator) in accumulators.iter().enumerate() {
                    for (v, &sum) in accumulator.iter().enumerate() {
                        Self::store(out.add(r * call.ldo + v * width), sum, masks[v]);
                    }
                }
            }
        }
    }

    pub(super) struct Avx512;

    impl Lanes for Avx512 {
        type Vector = __m512d;
        type Mask = __mmask8;
        const WIDTH: usize = 8;
        #[inline(always)]
        unsafe fn mask(count: usize) -> __mmask8 {
            (((1u16) << count) - 1) as __mmask8
        }
        #[inline(always)]
        unsafe fn load(pointer: *const f64, mask: __mmask8) -> __m512d {
            // SAFETY: only the lanes in `mask` are read.
            unsafe { _mm512_maskz_loadu_pd(mask, pointer) }
        }
        #[inline(always)]
        unsafe fn store(pointer: *mut f64, value: __m512d, mask: __mmask8) {
            // SAFETY: only the lanes in `mask` are written.
            unsafe { _mm512_mask_storeu_pd(pointer, mask, value) }
        }
        #[inline(always)]
        unsafe fn splat(value: f64) -> __m512d {
            // SAFETY: the instruction set was detected before any kernel runs.
            unsafe { _mm512_set1_pd(value) }
        }
        #[inline(always)]
        unsafe fn zero() -> __m512d {
            // SAFETY: the instruction set was detected before any kernel runs.
            unsafe { _mm512_setzero_pd() }
        }
        #[inline(always)]
        unsafe fn fmadd(a: __m512d, b: __m512d, c: __m512d) -> __m512d {
            // SAFETY: the instruction set was detected before any kernel runs.
            unsafe { _mm512_fmadd_pd(a, b, c) }
        }
    }

    pub(super) struct Avx2;

    impl Lanes for Avx2 {
        type Vector = __m256d;
        type Mask = __m256i;
        const WIDTH: usize = 4;
        #[inline(always)]
        unsafe fn mask(count: usize) -> __m256i {
            let lane = |i: usize| if i < count { -1i64 } else { 0 };
            // SAFETY: the instruction set was detected before any kernel runs.
            unsafe { _mm256_setr_epi64x(lane(0), lane(1), lane(2), lane(3)) }
        }
        #[inline(always)]
        unsafe fn load(pointer: *const f64, mask: __m256i) -> __m256d {
            // SAFETY: only the lanes in `mask` are read.
            unsafe { _mm256_maskload_pd(pointer, mask) }
        }
        #[inline(always)]
        unsafe fn store(pointer: *mut f64, value: __m256d, mask: __m256i) {
            // SAFETY: only the lanes in `mask` are written.
            unsafe { _mm256_maskstore_pd(pointer, mask, value) }
        }
        #[inline(always)]
        unsafe fn splat(value: f64) -> __m256d {
            // SAFETY: the instruction set was detected before any kernel runs.
            unsafe { _mm256_set1_pd(value) }
        }
        #[inline(always)]
        unsafe fn zero() -> __m256d {
            // SAFETY: the instruction set was detected before any kernel runs.
            unsafe { _mm256_setzero_pd() }
        }
        #[inline(always)]
        unsafe fn fmadd(a: __m256d, b: __m256d, c: __m256d) -> __m256d {
            // SAFETY: the instruction set was detected before any kernel runs.
            unsafe { _mm256_fmadd_pd(a, b, c) }
        }
    }
}

/// Cephes' rational approximations of erf (|u| < 1: u·T(u²)/U(u²)) and erfc (1 ≤ |u|:
/// exp(−u²)·P(|u|)/Q(|u|)); U and Q have an implicit leading 1.
#[allow(clippy::excessive_precision, clippy::unreadable_literal)]
const ERF_T: [f64; 5] = [
    9.60497373987051638749E0,
    9.00260197203842689217E1,
    2.23200534594684319226E3,
    7.00332514112805075473E3,
    5.55923013010394962768E4,
];
#[allow(clippy::excessive_precision, clippy::unreadable_literal)]
const ERF_U: [f64; 5] = [
    3.35617141647503099647E1,
    5.21357949780152679795E2,
    4.59432382970980127987E3,
    2.26290000613890934246E4,
    4.92673942608635921086E4,
];
#[allow(clippy::excessive_precision, clippy::unreadable_literal)]
const ERFC_P: [f64; 9] = [
    2.46196981473530512524E-10,
    5.64189564831068821977E-1,
    7.46321056442269912687E0,
    4.86371970985681366614E1,
    1.96520832956077098242E2,
    5.26445194995477358631E2,
    9.34528527171957607540E2,
    1.02755188689515710272E3,
    5.57535335369399327526E2,
];
#[allow(clippy::excessive_precision, clippy::unreadable_literal)]
const ERFC_Q: [f64; 8] = [
    1.32281951154744992508E1,
    8.67072140885989742329E1,
    3.54937778887819891062E2,
    9.75708501743205489753E2,
    1.82390916687909736289E3,
    2.24633760818710981792E3,
    1.65666309194161350182E3,
    5.57535340817727675546E2,
];

/// Horner's rule with fused multiply-adds, highest degree first.
#[inline(always)]
fn polynomial(x: f64, coefficients: &[f64]) -> f64 {
    coefficients[1..]
        .iter()
        .fold(coefficients[0], |sum, &c| sum.mul_add(x, c))
}

/// The same with an implicit leading coefficient 1.
#[inline(always)]
fn monic_polynomial(x: f64, coefficients: &[f64]) -> f64 {
    coefficients.iter().fold(1.0, |sum, &c| sum.mul_add(x, c))
}

/// exp(x) for x ≤ 0 without a branch (x below −708 gives exp(−708)): x = n·ln 2 + r with
/// |r| ≤ ln 2 / 2, e^r by its Taylor series to degree 13 (truncation below 1e-17), 2ⁿ from bits.
#[inline(always)]
fn exp_non_positive(x: f64) -> f64 {
    const MAGIC: f64 = 6_755_399_441_055_744.0; // 1.5·2⁵²: adding it rounds to an integer.
    const LN2_HIGH: f64 = 6.931_471_803_691_238e-1;
    const LN2_LOW: f64 = 1.908_214_929_270_587_7e-10;
    const INVERSE_FACTORIALS: [f64; 14] = [
        1.0 / 6_227_020_800.0,
        1.0 / 479_001_600.0,
        1.0 / 39_916_800.0,
        1.0 / 3_628_800.0,
        1.0 / 362_880.0,
        1.0 / 40_320.0,
        1.0 / 5_040.0,
        1.0 / 720.0,
        1.0 / 120.0,
        1.0 / 24.0,
        1.0 / 6.0,
        0.5,
        1.0,
        1.0,
    ];
    let x = x.max(-708.0);
    let shifted = x.mul_add(std::f64::consts::LOG2_E, MAGIC);
    let n = shifted - MAGIC;
    let r = (-n).mul_add(LN2_LOW, (-n).mul_add(LN2_HIGH, x));
    // The low mantissa bits of `shifted` hold n; (n + 1023) << 52 is 2ⁿ.
    let scale = f64::from_bits(shifted.to_bits().wrapping_add(1023) << 52);
    polynomial(r, &INVERSE_FACTORIALS) * scale
}

/// Whether GELU(z) takes erf's small-argument approximation: |u| < 1 with u = z/√2.
#[inline(always)]
fn erf_small_branch(z: f64) -> bool {
    (z * std::f64::consts::FRAC_1_SQRT_2).abs() < 1.0
}

/// Which of erf's two rational approximations [`gelu_branches`] evaluates.
#[derive(Clone, Copy, PartialEq, Eq)]
enum ErfBranches {
    /// Both, the lane's own selected afterwards (branch-free, for mixed chunks).
    Both,
    /// Only u·T(u²)/U(u²): every lane has |u| < 1.
    Small,
    /// Only exp(−u²)·P(|u|)/Q(|u|): no lane has |u| < 1.
    Large,
}

/// (GELU(z), GELU′(z), GELU″(z)) = (z·Φ(z), Φ(z) + z·φ(z), φ(z)·(2 − z²)) with one exponential,
/// branch-free so that it vectorises.
#[inline(always)]
pub(crate) fn gelu_with_derivatives(z: f64) -> (f64, f64, f64) {
    gelu_branches(z, ErfBranches::Both)
}

/// [`gelu_with_derivatives`] evaluating only the rational approximation(s) `branches` names; for
/// a lane of that kind the result is the same to the bit (the same operations in the same order).
#[inline(always)]
fn gelu_branches(z: f64, branches: ErfBranches) -> (f64, f64, f64) {
    const FRAC_1_SQRT_2PI: f64 = 0.398_942_280_401_432_7;
    let u = z * std::f64::consts::FRAC_1_SQRT_2;
    let magnitude = u.abs();
    let gaussian = exp_non_positive(-0.5 * z * z);
    let square = u * u;
    // One division: erf(u) = u·T(u²)/U(u²) for |u| < 1, else erfc(|u|) = e^{−u²}·P(|u|)/Q(|u|).
    let small_ratio = || {
        (
            u * polynomial(square, &ERF_T),
            monic_polynomial(square, &ERF_U),
        )
    };
    let large_ratio = || {
        (
            gaussian * polynomial(magnitude, &ERFC_P),
            monic_polynomial(magnitude, &ERFC_Q),
        )
    };
    let (small, (numerator, denominator)) = match branches {
        ErfBranches::Small => (true, small_ratio()),
        ErfBranches::Large => (false, large_ratio()),
        ErfBranches::Both => {
            let small = erf_small_branch(z);
            let (small_part, large_part) = (small_ratio(), large_ratio());
            (small, if small { small_part } else { large_part })
        }
    };
    let ratio = numerator / denominator;
    let tail = 0.5 * ratio;
    let cdf = if small {
        0.5 + tail
    } else if u > 0.0 {
        1.0 - tail
    } else {
        tail
    };
    let pdf = FRAC_1_SQRT_2PI * gaussian;
    (z * cdf, cdf + z * pdf, pdf * (2.0 - z * z))
}

/// For each pre-activation z in `values`: values ← GELU(z), first ← GELU′(z), and, when `second`
/// is given, second ← GELU″(z) (only the Hessian-vector product needs it). Every value is the
/// same to the bit with or without `second`.
pub(crate) fn gelu_layer(values: &mut [f64], first: &mut [f64], second: Option<&mut [f64]>) {
    let count = values.len();
    assert!(first.len() >= count);
    let first = &mut first[..count];
    match second {
        Some(second) => {
            assert!(second.len() >= count);
            gelu_layer_dispatched::<true>(values, first, &mut second[..count]);
        }
        None => gelu_layer_dispatched::<false>(values, first, &mut []),
    }
}

fn gelu_layer_dispatched<const SECOND: bool>(
    values: &mut [f64],
    first: &mut [f64],
    second: &mut [f64],
) {
    // SAFETY: the instruction set was detected.
    unsafe {
        match isa() {
            #[cfg(target_arch = "x86_64")]
            Isa::Avx512 => gelu_layer_avx512::<SECOND>(values, first, second),
            #[cfg(target_arch = "x86_64")]
            Isa::Avx2 => gelu_layer_avx2::<SECOND>(values, first, second),
            Isa::Portable => gelu_layer_portable::<SECOND>(values, first, second),
        }
    }
}

#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx512f,fma")]
fn gelu_layer_avx512<const SECOND: bool>(
    values: &mut [f64],
    first: &mut [f64],
    second: &mut [f64],
) {
    gelu_layer_portable::<SECOND>(values, first, second);
}

#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2,fma")]
fn gelu_layer_avx2<const SECOND: bool>(values: &mut [f64], first: &mut [f64], second: &mut [f64]) {
    gelu_layer_portable::<SECOND>(values, first, second);
}

/// One chunk of lanes with the rational approximation(s) fixed at compile time (BRANCHES: 0 both,
/// 1 small, 2 large), so that the lane loop vectorises; GELU″ is stored when SECOND.
#[inline(always)]
fn gelu_chunk<const LANES: usize, const BRANCHES: u8, const SECOND: bool>(
    v: &mut [f64; LANES],
    d1: &mut [f64; LANES],
    d2: &mut [f64],
) {
    let branches = match BRANCHES {
        1 => ErfBranches::Small,
        2 => ErfBranches::Large,
        _ => ErfBranches::Both,
    };
    for lane in 0..LANES {
        let (h, g1, g2) = gelu_branches(v[lane], branches);
        v[lane] = h;
        d1[lane] = g1;
        if SECOND {
            d2[lane] = g2;
        }
    }
}

#[inline(always)]
fn gelu_layer_portable<const SECOND: bool>(
    values: &mut [f64],
    first: &mut [f64],
    second: &mut [f64],
) {
    const LANES: usize = 8;
    let count = values.len();
    for start in (0..count - count % LANES).step_by(LANES) {
        let chunk = start..start + LANES;
        let v: &mut [f64; LANES] = (&mut values[chunk.clone()]).try_into().expect("chunk");
        let d1: &mut [f64; LANES] = (&mut first[chunk.clone()]).try_into().expect("chunk");
        let d2: &mut [f64] = if SECOND { &mut second[chunk] } else { &mut [] };
        // A chunk whose lanes all fall on one side of |u| = 1 evaluates one rational
        // approximation instead of both (hidden pre-activations are mostly small).
        if v.iter().all(|&z| erf_small_branch(z)) {
            gelu_chunk::<LANES, 1, SECOND>(v, d1, d2);
        } else if v.iter().all(|&z| !erf_small_branch(z)) {
            gelu_chunk::<LANES, 2, SECOND>(v, d1, d2);
        } else {
            gelu_chunk::<LANES, 0, SECOND>(v, d1, d2);
        }
    }
    for k in count - count % LANES..count {
        let (h, g1, g2) = gelu_with_derivatives(values[k]);
        values[k] = h;
        first[k] = g1;
        if SECOND {
            second[k] = g2;
        }
    }
}

/// out (cols × rows, row-major) = source (rows × cols, row-major)ᵀ. With AVX2 (or AVX-512), 4 × 4
/// blocks go through registers (four loads, eight shuffles, four stores); the rows and columns
/// beyond the last whole block, and machines without AVX2, take the scalar loop.
pub(crate) fn transpose(rows: usize, cols: usize, source: &[f64], out: &mut [f64]) {
    let (source, out) = (&source[..rows * cols], &mut out[..rows * cols]);
    #[cfg(target_arch = "x86_64")]
    if isa() != Isa::Portable {
        // SAFETY: AVX2 was detected (AVX-512 machines have it too).
        unsafe { transpose_avx2(rows, cols, source, out) };
        return;
    }
    transpose_scalar(rows, cols, source, out, 0, 0);
}

/// The scalar transpose of the elements with row ≥ `from_row` or column ≥ `from_col`: contiguous
/// writes, strided reads (measured faster than the converse and than 8 × 8 scalar blocks).
fn transpose_scalar(
    rows: usize,
    cols: usize,
    source: &[f64],
    out: &mut [f64],
    from_row: usize,
    from_col: usize,
) {
    for (c, out_row) in out.chunks_exact_mut(rows).enumerate() {
        let first_row = if c < from_col { from_row } else { 0 };
        for (value, source_row) in out_row[first_row..]
            .iter_mut()
            .zip(source.chunks_exact(cols).skip(first_row))
        {
            *value = source_row[c];
        }
    }
}

#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2")]
fn transpose_avx2(rows: usize, cols: usize, source: &[f64], out: &mut [f64]) {
    use std::arch::x86_64::*;
    let (block_rows, block_cols) = (rows / 4 * 4, cols / 4 * 4);
    let (from, to) = (source.as_ptr(), out.as_mut_ptr());
    for r in (0..block_rows).step_by(4) {
        for c in (0..block_cols).step_by(4) {
            // SAFETY: r + 3 < rows and c + 3 < cols, so the four loads of source rows r..r+4 at
            // columns c..c+4 and the four stores of out rows c..c+4 at columns r..r+4 stay
            // inside the slices (both rows × cols, row-major).
            unsafe {
                let first = from.add(r * cols + c);
                let a = _mm256_loadu_pd(first);
                let b = _mm256_loadu_pd(first.add(cols));
                let e = _mm256_loadu_pd(first.add(2 * cols));
                let d = _mm256_loadu_pd(first.add(3 * cols));
                // Rows (a0 a1 a2 a3), (b…), (e…), (d…) → columns (a0 b0 e0 d0), ….
                let low_ab = _mm256_unpacklo_pd(a, b); // a0 b0 a2 b2
                let high_ab = _mm256_unpackhi_pd(a, b); // a1 b1 a3 b3
                let low_ed = _mm256_unpacklo_pd(e, d); // e0 d0 e2 d2
                let high_ed = _mm256_unpackhi_pd(e, d); // e1 d1 e3 d3
                let target = to.add(c * rows + r);
                _mm256_storeu_pd(target, _mm256_permute2f128_pd(low_ab, low_ed, 0x20));
                _mm256_storeu_pd(
                    target.add(rows),
                    _mm256_permute2f128_pd(high_ab, high_ed, 0x20),
                );
                _mm256_storeu_pd(
                    target.add(2 * rows),
                    _mm256_permute2f128_pd(low_ab, low_ed, 0x31),
                );
                _mm256_storeu_pd(
                    target.add(3 * rows),
                    _mm256_permute2f128_pd(high_ab, high_ed, 0x31),
                );
            }
        }
    }
    if block_rows < rows || block_cols < cols {
        transpose_scalar(rows, cols, source, out, block_rows, block_cols);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn vectorised_gelu_matches_libm_and_every_build_agrees() {
        let mut z: Vec<f64> = (-4000..=4000).map(|k| k as f64 * 0.004).collect();
        // Chunks of eight mixing both sides of |u| = 1 (|z| = √2), not only the boundary chunks.
        z.extend((0..64).map(|k| if k % 3 == 0 { 0.3 } else { -2.5 } * (1.0 + k as f64 * 0.01)));
        z.extend([-40.0, -12.0, -9.0, 9.0, 12.0, 40.0, 1e-300, -1e-300, 0.0]);
        let (mut values, mut first, mut second) =
            (z.clone(), vec![0.0; z.len()], vec![0.0; z.len()]);
        gelu_layer(&mut values, &mut first, Some(&mut second));
        let (mut portable, mut portable_first, mut portable_second) =
            (z.clone(), vec![0.0; z.len()], vec![0.0; z.len()]);
        gelu_layer_portable::<true>(&mut portable, &mut portable_first, &mut portable_second);
        assert_eq!(
            (&values, &first, &second),
            (&portable, &portable_first, &portable_second)
        );
        // Without GELU″: the same values and GELU′ to the bit.
        let (mut values_only, mut first_only) = (z.clone(), vec![0.0; z.len()]);
        gelu_layer(&mut values_only, &mut first_only, None);
        assert_eq!((&values_only, &first_only), (&values, &first));
        for (k, &x) in z.iter().enumerate() {
            // Chunks evaluating one rational approximation give the bits of the branch-free code.
            assert_eq!(
                gelu_with_derivatives(x),
                (values[k], first[k], second[k]),
                "z = {x}"
            );
            let exact = (
                crate::gelu(x),
                crate::gelu_derivative(x),
                crate::gelu_second_derivative(x),
            );
            for (got, want) in [
                (values[k], exact.0),
                (first[k], exact.1),
                (second[k], exact.2),
            ] {
                assert!(
                    (got - want).abs() <= 1e-14 * want.abs().max(0.1),
                    "z = {x}: {got} vs {want}"
                );
            }
        }
    }

    fn values(count: usize, seed: f64) -> Vec<f64> {
        (0..count)
            .map(|k| ((k as f64 + seed) * 0.731).sin())
            .collect()
    }

    #[test]
    fn column_sums_add_each_column_in_row_order() {
        for &(rows, width) in &[(1, 1), (64, 120), (64, 12), (5, 41), (3, 20)] {
            let matrix = values(rows * width, 4.0);
            let mut out = vec![f64::NAN; width];
            column_sums(&matrix, width, &mut out);
            for (c, &sum) in out.iter().enumerate() {
                let want = (0..rows).fold(0.0, |total, r| total + matrix[r * width + c]);
                assert_eq!(sum, want, "{rows}x{width} column {c}");
            }
        }
    }

    #[test]
    fn transpose_moves_every_element_in_blocks_and_at_the_edges() {
        for &(rows, cols) in &[(1, 1), (4, 4), (12, 16), (48, 120), (5, 9), (13, 6), (3, 8)] {
            let source = values(rows * cols, 3.0);
            let mut out = vec![f64::NAN; rows * cols];
            transpose(rows, cols, &source, &mut out);
            let mut scalar = vec![f64::NAN; rows * cols];
            transpose_scalar(rows, cols, &source, &mut scalar, 0, 0);
            for r in 0..rows {
                for c in 0..cols {
                    assert_eq!(
                        out[c * rows + r],
                        source[r * cols + c],
                        "{rows}x{cols} ({r}, {c})"
                    );
                    assert_eq!(scalar[c * rows + r], source[r * cols + c]);
                }
            }
        }
    }

    #[test]
    fn matmul_matches_the_naive_product_and_every_build_agrees_bit_for_bit() {
        for &(rows, cols, depth) in &[
            (1, 1, 1),
            (7, 13, 5),
            (64, 120, 48),
            (10, 20, 64),
            (9, 33, 3),
        ] {
            let a = values(rows * depth, 1.0);
            let b = values(depth * cols, 2.0);
            let initial = values(rows * cols, 3.0);
            for accumulate in [false, true] {
                for transposed in [false, true] {
                    let (a_used, strides) = if transposed {
                        let mut t = vec![0.0; rows * depth];
                        transpose(rows, depth, &a, &mut t);
                        (
                            t,
                            Strides {
                                row: 1,
                                depth: rows,
                            },
                        )
                    } else {
                        (
                            a.clone(),
                            Strides {
                                row: depth,
                                depth: 1,
                            },
                        )
                    };
                    let mut fast = initial.clone();
                    matmul(
                        rows, cols, depth, &a_used, strides, &b, cols, &mut fast, cols, accumulate,
                    );
                    let mut portable = initial.clone();
                    matmul_portable(
                        rows,
                        cols,
                        depth,
                        &a_used,
                        strides,
                        &b,
                        cols,
                        &mut portable,
                        cols,
                        accumulate,
                    );
                    assert_eq!(fast, portable);
                    for r in 0..rows {
                        for c in 0..cols {
                            let mut expected = if accumulate {
                                initial[r * cols + c]
                            } else {
                                0.0
                            };
                            for k in 0..depth {
                                expected += a[r * depth + k] * b[k * cols + c];
                            }
                            assert!((fast[r * cols + c] - expected).abs() < 1e-12);
                        }
                    }
                }
            }
        }
    }
}
