//! Kernels on small `t×t` blocks (`t` = rows per pose): packed symmetric
//! storage, Cholesky in place with a pivot floor (plain and pivoted), and the
//! block determinants of the add, remove and exchange updates, eqs.
//! (17)–(22). Row-major, sequential, no allocation for `t ≤`
//! [`STACK_T`]; larger blocks (several markers per pose) use the heap.
//! Triangular loops run over half-open ranges (`0..r + 1`, not `0..=r`):
//! an inclusive range's extra test per step was 10 % of a full-pose
//! exchange scan (`select --robot ur5:pose --ils 1`: 1.69 → 1.53 s).

/// Largest rows-per-pose `t` whose `t×t` scratch lives on the stack (a
/// point is 3, a full pose 6); larger blocks are allocated.
pub(crate) const STACK_T: usize = 6;

/// Scratch of `len` values: on the stack up to `N`, on the heap above, so
/// that the kernels take any `t` without a cap and without allocating in
/// the common case.
pub(crate) enum Scratch<T: Copy + Default, const N: usize> {
    /// Up to `N` values, the first `.1` in use.
    Stack([T; N], usize),
    /// More than `N` values.
    Heap(Vec<T>),
}

impl<T: Copy + Default, const N: usize> Scratch<T, N> {
    /// `len` values, all `T::default()`.
    #[inline]
    pub(crate) fn new(len: usize) -> Self {
        if len <= N {
            Scratch::Stack([T::default(); N], len)
        } else {
            Scratch::Heap(vec![T::default(); len])
        }
    }
}

impl<T: Copy + Default, const N: usize> std::ops::Deref for Scratch<T, N> {
    type Target = [T];
    #[inline]
    fn deref(&self) -> &[T] {
        match self {
            Scratch::Stack(a, n) => &a[..*n],
            Scratch::Heap(v) => v,
        }
    }
}

impl<T: Copy + Default, const N: usize> std::ops::DerefMut for Scratch<T, N> {
    #[inline]
    fn deref_mut(&mut self) -> &mut [T] {
        match self {
            Scratch::Stack(a, n) => &mut a[..*n],
            Scratch::Heap(v) => v,
        }
    }
}

/// A `t×t` block's scratch: on the stack up to `STACK_T × STACK_T` (a test
/// checks it, so that `*` as `/`, the same numbers from the heap, is caught).
pub(crate) type BlockScratch = Scratch<f64, { STACK_T * STACK_T }>;
/// A permutation of `t` rows.
pub(crate) type PermScratch = Scratch<usize, STACK_T>;

/// Length of the packed lower triangle of a `t×t` symmetric matrix.
#[inline]
pub(crate) const fn packed_len(t: usize) -> usize {
    t * (t + 1) / 2
}

/// Index of entry `(a, b)`, `b ≤ a`, in the packed lower triangle (by rows).
#[inline]
pub(crate) const fn pk(a: usize, b: usize) -> usize {
    a * (a + 1) / 2 + b
}

/// Cholesky `A = L Lᵀ` in place of a row-major `n×n` symmetric matrix
/// (lower triangle read and overwritten by `L`). Returns `ln det A` when every
/// pivot `d_k = L_kk²` exceeds `floor`, else `Err(d_k)` for the first pivot
/// that does not (NaN pivots fail too).
#[inline]
pub(crate) fn chol_in_place(a: &mut [f64], n: usize, floor: f64) -> Result<f64, f64> {
    let mut ln_det = 0.0;
    chol_pivots_in_place(a, n, floor, |d| ln_det += d.ln())?;
    Ok(ln_det)
}

/// The Cholesky factorization of [`chol_in_place`], handing each pivot
/// `d_k = L_kk²` to `pivot` (so a caller can take their product and one `ln`
/// instead of `n` of them); `Err(d_k)` for the first pivot `≤ floor`.
#[inline]
pub(crate) fn chol_pivots_in_place(
    a: &mut [f64],
    n: usize,
    floor: f64,
    mut pivot: impl FnMut(f64),
) -> Result<(), f64> {
    for k in 0..n {
        let mut d = a[k * n + k];
        for j in 0..k {
            d -= a[k * n + j] * a[k * n + j];
        }
        if !(d > floor) {
            return Err(d);
        }
        pivot(d);
        let lkk = d.sqrt();
        a[k * n + k] = lkk;
        for i in k + 1..n {
            let mut s = a[i * n + k];
            for j in 0..k {
                s -= a[i * n + j] * a[k * n + j];
            }
            a[i * n + k] = s / lkk;
        }
    }
    Ok(())
}

/// Cholesky with diagonal (complete symmetric) pivoting, `P A Pᵀ = L Lᵀ`, in
/// place of a row-major `n×n` symmetric matrix whose *both* triangles are
/// set; `L` ends in the lower triangle and `perm[k]` is the original index of
/// position `k`. Returns `ln det A`, or `Err(d)` for the first pivot
/// `d ≤ floor` — after choosing the largest remaining diagonal, so the first
/// failing pivot is the largest remaining one.
///
/// Used for the removal Schur complement `B = I − S`: without pivoting, a
/// small early pivot amplifies the rounding of the later ones (a projection
/// `I − vvᵀ/‖v‖²` can show a zero pivot as `1e-11`); with pivoting the small
/// pivots come last and carry only `≈ n·u·‖B‖` of rounding (Higham,
/// *Accuracy and Stability*, §10.3), so the singularity test is reliable.
#[inline]
pub(crate) fn chol_pivoted_in_place(
    a: &mut [f64],
    n: usize,
    floor: f64,
    perm: &mut [usize],
) -> Result<f64, f64> {
    let mut ln_det = 0.0;
    chol_pivoted_pivots_in_place(a, n, floor, perm, |d| ln_det += d.ln())?;
    Ok(ln_det)
}

/// The pivoted factorization of [`chol_pivoted_in_place`], handing each
/// pivot `d_k` to `pivot` (for one `ln` of their product, as
/// [`chol_pivots_in_place`] does); `Err(d)` for the first pivot `≤ floor`.
#[inline]
pub(crate) fn chol_pivoted_pivots_in_place(
    a: &mut [f64],
    n: usize,
    floor: f64,
    perm: &mut [usize],
    mut pivot: impl FnMut(f64),
) -> Result<(), f64> {
    for (k, pk) in perm.iter_mut().enumerate().take(n) {
        *pk = k;
    }
    for k in 0..n {
        // Largest remaining diagonal entry (first on ties: deterministic).
        // (`k + 1` as `k * 1` survives issue #30's mutation sample as
        // equivalent: the search then starts at `k` itself, which never beats
        // itself under the strict `>`.)
        let mut j = k;
        for i in k + 1..n {
            if a[i * n + i] > a[j * n + j] {
                j = i;
            }
        }
        if j != k {
            perm.swap(k, j);
            for c in 0..n {
                a.swap(k * n + c, j * n + c);
            }
            for r in k..n {
                a.swap(r * n + k, r * n + j);
            }
        }
        let d = a[k * n + k];
        if !(d > floor) {
            return Err(d);
        }
        pivot(d);
        let l = d.sqrt();
        a[k * n + k] = l;
        for i in k + 1..n {
            a[i * n + k] /= l;
        }
        // The Schur complement of the rows and columns after `k`. (`k + 1` as
        // `k * 1` survives issue #30's sample as equivalent: row `k` is then
        // also updated right of its diagonal, in the upper triangle, which
        // holds no part of `L` and which no later step reads: later swaps and
        // updates touch rows after `k` only.)
        for i in k + 1..n {
            let lik = a[i * n + k];
            for c in k + 1..n {
                a[i * n + c] -= lik * a[c * n + k];
            }
        }
    }
    Ok(())
}

/// Smallest LDLᵀ pivot of a Cholesky factor produced by [`chol_in_place`]
/// or [`chol_pivoted_in_place`].
#[inline]
pub(crate) fn min_pivot(l: &[f64], n: usize) -> f64 {
    (0..n)
        .map(|k| l[k * n + k] * l[k * n + k])
        .fold(f64::INFINITY, f64::min)
}

/// `det(I + V)` of a packed symmetric `3×3` block `V` (a point's add
/// block) by the pivots of its square-root-free `LDLᵀ`: branch-free, so a
/// loop over candidates vectorises; [`ln_det_i_plus`]'s value is the
/// logarithm of this one when it is finite and positive.
#[inline(always)]
pub(crate) fn det_i_plus3(v: &[f64]) -> f64 {
    let (a00, a10, a11) = (1.0 + v[0], v[1], 1.0 + v[2]);
    let (a20, a21, a22) = (v[3], v[4], 1.0 + v[5]);
    // With m1 = a00·d1, m2 = a00·(a22 − a20²/a00) and n = a00·u21 (the
    // pivots scaled by the first), d1·d2 = (m1·m2 − n²)/(a00·m1)·… reduces
    // to one division: det = a00·d1·d2 = (m1·m2 − n²)/a00.
    let m1 = a00 * a11 - a10 * a10;
    let m2 = a00 * a22 - a20 * a20;
    let n = a00 * a21 - a20 * a10;
    (m1 * m2 - n * n) / a00
}

/// `ln det(I + V)` for a packed PSD `t×t` block `V`: the add gain of
/// eq. (17)/(20) in block form. `I + V ⪰ I`, so the only failure is non-finite
/// input, reported as `-∞`.
///
/// The hot loop of every add scan, so it takes one `ln` and no square root:
/// `I + V = L D Lᵀ` (unit lower `L`, square-root-free), and
/// `ln det = ln Π d_k`. Every pivot of `I + V ⪰ I` is `≥ 1` in exact
/// arithmetic (a pivot is a Schur complement, and those of a matrix `⪰ I`
/// are `⪰ I`), so the product cannot underflow; it overflows only for
/// entries beyond ~1e100, where the pivots' logarithms are summed instead.
/// `t = 3` (points) is unrolled.
#[inline]
pub(crate) fn ln_det_i_plus(v: &[f64], t: usize) -> f64 {
    let det = if t == 3 {
        det_i_plus3(v)
    } else {
        let mut a_buf = BlockScratch::new(t * t);
        let mut d_buf = BlockScratch::new(t);
        let (a, d): (&mut [f64], &mut [f64]) = (&mut a_buf, &mut d_buf);
        for r in 0..t {
            for c in 0..r + 1 {
                let x = v[pk(r, c)];
                a[r * t + c] = if r == c { 1.0 + x } else { x };
            }
        }
        ldl_pivot_product(a, d, t)
    };
    // `det > 0.0` as `>=` survives issue #30's sample as equivalent: at
    // `det == 0` the mutant's `ln 0 = −∞` is the fallback's answer too (its
    // Cholesky at floor 0 refuses the zero pivot); the two factorizations
    // could disagree only on an exactly singular `I + V`, which needs an
    // eigenvalue −1 of `V`, never for the PSD blocks of the callers.
    if det.is_finite() && det > 0.0 {
        det.ln()
    } else if v[..packed_len(t)].iter().all(|x| x.is_finite()) {
        // Overflow of the product (or a pivot lost to rounding): the sum of
        // the pivots' logarithms.
        let mut a_buf = BlockScratch::new(t * t);
        let a: &mut [f64] = &mut a_buf;
        for r in 0..t {
            for c in 0..r + 1 {
                let x = v[pk(r, c)];
                a[r * t + c] = if r == c { 1.0 + x } else { x };
            }
        }
        chol_in_place(a, t, 0.0).unwrap_or(f64::NEG_INFINITY)
    } else {
        f64::NEG_INFINITY
    }
}

/// `Π d_k` of the square-root-free `A = L D Lᵀ` of a row-major `n×n`
/// symmetric matrix (lower triangle read, overwritten by `L`; `d` gets the
/// pivots). No pivoting: for matrices `⪰ I` (the add blocks) every pivot is
/// `≥ 1`.
#[inline]
fn ldl_pivot_product(a: &mut [f64], d: &mut [f64], n: usize) -> f64 {
    let mut prod = 1.0;
    for k in 0..n {
        let mut dk = a[k * n + k];
        for j in 0..k {
            dk -= a[k * n + j] * a[k * n + j] * d[j];
        }
        d[k] = dk;
        prod *= dk;
        let r = 1.0 / dk;
        for i in k + 1..n {
            let mut s = a[i * n + k];
            for j in 0..k {
                s -= a[i * n + j] * d[j] * a[k * n + j];
            }
            a[i * n + k] = s * r;
        }
    }
    prod
}

/// `ln det(I − V)` for a packed `t×t` block: the removal loss of
/// eq. (21)/(22) in block form; `Err(pivot)` when a pivot is `≤ floor`.
#[inline]
pub(crate) fn ln_det_i_minus(v: &[f64], t: usize, floor: f64) -> Result<f64, f64> {
    let mut a_buf = BlockScratch::new(t * t);
    let a: &mut [f64] = &mut a_buf;
    for r in 0..t {
        for c in 0..r + 1 {
            let x = v[pk(r, c)];
            a[r * t + c] = if r == c { 1.0 - x } else { -x };
            a[c * t + r] = a[r * t + c];
        }
    }
    let mut perm = PermScratch::new(t);
    chol_pivoted_in_place(a, t, floor, &mut perm)
}

/// First factor of the exchange determinant: the Cholesky factor of
/// `I + V_in` (row-major lower triangle in `la`) and `ln det(I + V_in)`.
pub(crate) fn exchange_in_factor(t: usize, v_in: &[f64], la: &mut [f64]) -> Result<f64, f64> {
    for r in 0..t {
        for c in 0..r + 1 {
            let x = v_in[pk(r, c)];
            la[r * t + c] = if r == c { 1.0 + x } else { x };
        }
    }
    chol_in_place(&mut la[..t * t], t, 0.0)
}

/// Smallest pivot of `I − V_out` for which a one-out exchange scan of points
/// prices through `(I − V_out)⁻¹` ([`removal_inverse_factor3`]). `I − V_out`
/// is dimensionless with `0 ⪯ I − V_out ⪯ I`, so its condition number is at
/// most `1/pivot`, and the scan's relative error about `ε/pivot ≈ 2e-12`
/// here: 50 times below the selection's improvement tolerance (1e-10).
pub(crate) const FAST_EXCHANGE_PIVOT: f64 = 1e-4;

/// For a packed `3×3` `V_out` whose removal is comfortably regular (every
/// pivot of `I − V_out` at least `min_pivot`): `ln det(I − V_out)` and the
/// upper triangular `U = L⁻ᵀ` (row-major) with `(I − V_out)⁻¹ = U Uᵀ`, where
/// `I − V_out = L Lᵀ`. Then exchanging `out` for `i` changes `ln det M` by
/// `ln det(I − V_out) + ln det(I + V_i + Z Zᵀ)` with `Z = W_i U`
/// (Woodbury: `V_i` after the removal is `V_i + W(I − V_out)⁻¹Wᵀ`), an add
/// gain ([`det_i_plus3`]) of an updated block, so a scan over candidates
/// needs no factorization per candidate. `None` below `min_pivot` (or for
/// non-finite input): the caller prices by [`exchange_ln_det`] instead.
pub(crate) fn removal_inverse_factor3(v: &[f64], min_pivot: f64) -> Option<(f64, [f64; 9])> {
    let (a00, a10, a11) = (1.0 - v[0], -v[1], 1.0 - v[2]);
    let (a20, a21, a22) = (-v[3], -v[4], 1.0 - v[5]);
    let d0 = a00;
    if !(d0 >= min_pivot) {
        return None;
    }
    let l00 = d0.sqrt();
    let (l10, l20) = (a10 / l00, a20 / l00);
    let d1 = a11 - l10 * l10;
    if !(d1 >= min_pivot) {
        return None;
    }
    let l11 = d1.sqrt();
    let l21 = (a21 - l20 * l10) / l11;
    let d2 = a22 - l20 * l20 - l21 * l21;
    if !(d2 >= min_pivot && d2.is_finite()) {
        return None;
    }
    let l22 = d2.sqrt();
    // L⁻¹ (lower), then U = L⁻ᵀ.
    let (i00, i11, i22) = (1.0 / l00, 1.0 / l11, 1.0 / l22);
    let i10 = -l10 * i00 * i11;
    let i21 = -l21 * i11 * i22;
    let i20 = -(l20 * i00 + l21 * i10) * i22;
    let u = [i00, i10, i20, 0.0, i11, i21, 0.0, 0.0, i22];
    Some(((d0 * d1 * d2).ln(), u))
}

/// [`removal_inverse_factor3`] for any `t`: `ln det(I − V_out)` and
/// `U = L⁻ᵀ` (row-major `t×t`, upper triangular), or `None` when a pivot
/// of `I − V_out` is below `min_pivot`.
pub(crate) fn removal_inverse_factor(
    v: &[f64],
    t: usize,
    min_pivot: f64,
) -> Option<(f64, Vec<f64>)> {
    if t == 3 {
        return removal_inverse_factor3(v, min_pivot).map(|(l, u)| (l, u.to_vec()));
    }
    let mut a = vec![0.0; t * t];
    for r in 0..t {
        for c in 0..r + 1 {
            a[r * t + c] = f64::from(u8::from(r == c)) - v[pk(r, c)];
        }
    }
    let mut prod = 1.0;
    chol_pivots_in_place(&mut a, t, min_pivot, |d| prod *= d).ok()?;
    // L⁻¹ column by column (forward substitution), then U = L⁻ᵀ.
    let mut u = vec![0.0; t * t];
    for c in 0..t {
        for r in c..t {
            let mut s = f64::from(u8::from(r == c));
            for k in c..r {
                s -= a[r * t + k] * u[c * t + k];
            }
            // u[c][r] holds L⁻¹[r][c]: U = L⁻ᵀ directly.
            u[c * t + r] = s / a[r * t + r];
        }
    }
    prod.is_finite().then(|| (prod.ln(), u))
}

/// [`variance_after_removal3`] for any `t`: the packed `V_i + Z Zᵀ`,
/// `Z = W U`, into `out` (`w`, `u` row-major `t×t`).
pub(crate) fn variance_after_removal(v: &[f64], w: &[f64], u: &[f64], t: usize, out: &mut [f64]) {
    let mut z_buf = BlockScratch::new(t * t);
    let z: &mut [f64] = &mut z_buf;
    for r in 0..t {
        for c in 0..t {
            let mut s = 0.0;
            // `+=` as `-=` survives issue #30's sample as equivalent: it gives
            // `Z = −W U`, and only `Z Zᵀ` is used.
            for k in 0..c + 1 {
                s += w[r * t + k] * u[k * t + c];
            }
            z[r * t + c] = s;
        }
    }
    for r in 0..t {
        for q in 0..r + 1 {
            let mut s = v[pk(r, q)];
            for c in 0..t {
                s += z[r * t + c] * z[q * t + c];
            }
            out[pk(r, q)] = s;
        }
    }
}

/// The packed `V_i + Z Zᵀ`, `Z = W U` (`w` row-major `3×3`, the cross block
/// `X_i M⁻¹ X_outᵀ`; `u` from [`removal_inverse_factor3`]): the variance
/// of candidate `i` once `out` is removed.
#[inline(always)]
pub(crate) fn variance_after_removal3(v: &[f64], w: &[f64; 9], u: &[f64; 9]) -> [f64; 6] {
    let mut z = [0.0; 9];
    for r in 0..3 {
        for c in 0..3 {
            // U is upper triangular: U[k][c] = 0 for k > c.
            let mut s = 0.0;
            // `+=` as `-=`: equivalent, as in `variance_after_removal` (`Z Zᵀ`).
            for k in 0..c + 1 {
                s += w[r * 3 + k] * u[k * 3 + c];
            }
            z[r * 3 + c] = s;
        }
    }
    let zz = |r: usize, s: usize| {
        z[r * 3] * z[s * 3] + z[r * 3 + 1] * z[s * 3 + 1] + z[r * 3 + 2] * z[s * 3 + 2]
    };
    [
        v[0] + zz(0, 0),
        v[1] + zz(1, 0),
        v[2] + zz(1, 1),
        v[3] + zz(2, 0),
        v[4] + zz(2, 1),
        v[5] + zz(2, 2),
    ]
}

/// Size below which an unpivoted pivot of the exchange's Schur complement
/// `B` is re-examined with pivoting ([`exchange_out_ln_det`]). `B` is
/// dimensionless, `0 ⪯ B ⪯ I + YᵀY`, with pivots of order 0.01–1 away from
/// singularity.
pub(crate) const SUSPECT_PIVOT: f64 = 1e-6;

/// Second factor of the exchange determinant: `ln det(I − V_out + YᵀY)`
/// with `Y = L_A⁻¹ W` (`la` from [`exchange_in_factor`], `w(a, b)` the cross
/// block `X_in M⁻¹ X_outᵀ`), with one `ln` of the product of its pivots.
/// `Err(pivot)` for a pivot `≤ floor`.
///
/// `B` is the removal Schur complement, singular exactly when the exchange
/// loses rank, and the singularity test needs pivoting (see
/// [`chol_pivoted_in_place`]): an unpivoted zero pivot can come out as
/// `1e-8`. Pivoting every candidate costs 16% of the pricing, so the plain
/// Cholesky runs first and its answer stands only when every pivot exceeds
/// [`SUSPECT_PIVOT`] — a polluted zero needs an earlier pivot about that
/// small to be amplified that far. Otherwise (and on refusal) the pivoted
/// factorization decides, as the state's update does.
pub(crate) fn exchange_out_ln_det(
    t: usize,
    la: &[f64],
    v_out: &[f64],
    w: impl Fn(usize, usize) -> f64,
    floor: f64,
) -> Result<f64, f64> {
    // Y = L_A⁻¹ W (t×t, row-major), forward substitution column by column.
    let mut y_buf = BlockScratch::new(t * t);
    let y: &mut [f64] = &mut y_buf;
    for c in 0..t {
        for r in 0..t {
            let mut s = w(r, c);
            for j in 0..r {
                s -= la[r * t + j] * y[j * t + c];
            }
            y[r * t + c] = s / la[r * t + r];
        }
    }
    // B = I − V_out + Yᵀ Y; `upper` also fills the upper triangle, which
    // only the pivoted factorization reads.
    let fill = |b: &mut [f64], upper: bool| {
        for r in 0..t {
            for c in 0..r + 1 {
                let mut s = if r == c { 1.0 } else { 0.0 } - v_out[pk(r, c)];
                for j in 0..t {
                    s += y[j * t + r] * y[j * t + c];
                }
                b[r * t + c] = s;
                if upper {
                    b[c * t + r] = s;
                }
            }
        }
    };
    // The pivots are in (floor, ~1+‖Y‖²] (B ⪯ I + YᵀY), so their product
    // (t of them, each at most ~1+‖Y‖², so for any practical t) neither overflows nor underflows.
    let mut b_buf = BlockScratch::new(t * t);
    let b: &mut [f64] = &mut b_buf;
    fill(b, false);
    let (mut det, mut lo) = (1.0f64, f64::INFINITY);
    let plain = chol_pivots_in_place(b, t, floor, |d| {
        det *= d;
        lo = lo.min(d);
    });
    // `lo == SUSPECT_PIVOT` for `>` survives the mutation sample (issue
    // #30) as equivalent in value: it sends every candidate to the pivoted
    // factorization below, which gives the same determinant up to rounding
    // and is the reference the fast path defers to; it costs time only (a
    // refusal could differ only for a pivoted pivot `≤ floor` behind plain
    // pivots all above SUSPECT_PIVOT, the case the fast path accepts).
    if plain.is_ok() && lo > SUSPECT_PIVOT {
        return Ok(det.ln());
    }
    fill(b, true);
    let mut det = 1.0;
    let mut perm = PermScratch::new(t);
    chol_pivoted_pivots_in_place(b, t, floor, &mut perm, |d| det *= d)?;
    Ok(det.ln())
}

/// Exchange gain `ln det [[I + V_in, W], [−Wᵀ, I − V_out]]` by block
/// elimination, `det(I + V_in) · det(I − V_out + Wᵀ(I + V_in)⁻¹W)`;
/// `Err(pivot)` when the result is numerically singular.
pub(crate) fn exchange_ln_det(
    t: usize,
    v_in: &[f64],
    v_out: &[f64],
    w: impl Fn(usize, usize) -> f64,
    floor: f64,
) -> Result<f64, f64> {
    let mut la = BlockScratch::new(t * t);
    let ln_a = exchange_in_factor(t, v_in, &mut la)?;
    Ok(ln_a + exchange_out_ln_det(t, &la, v_out, w, floor)?)
}

#[cfg(test)]
mod tests;
