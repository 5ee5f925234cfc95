//! Small fixed-size dense linear algebra in `f64`: just what the planners
//! need (products, a pivoted solve, the matrix exponential and its
//! integral). Dimensions are const generics, so nothing allocates and every
//! loop is bounded by the array types.

use kinematics_core::numeric::back_substitute;

/// A column vector of `N` components.
pub type Vector<const N: usize> = [f64; N];
/// A matrix with `R` rows and `C` columns, row-major.
pub type Matrix<const R: usize, const C: usize> = [[f64; C]; R];

/// Component `i` of `v`, or 0 when out of range (callers only pass indices
/// bounded by the array length; this keeps the code free of panicking
/// indexing).
#[inline]
pub(crate) fn at(v: &[f64], i: usize) -> f64 {
    v.get(i).copied().unwrap_or(0.0)
}

/// Element `(i, j)` of `m`, or 0 when out of range.
#[inline]
pub(crate) fn at2<const R: usize, const C: usize>(m: &Matrix<R, C>, i: usize, j: usize) -> f64 {
    m.get(i).and_then(|row| row.get(j)).copied().unwrap_or(0.0)
}

/// The `N × N` identity.
pub fn identity<const N: usize>() -> Matrix<N, N> {
    core::array::from_fn(|i| core::array::from_fn(|j| if i == j { 1.0 } else { 0.0 }))
}

/// `a · b`.
pub fn mat_mul<const R: usize, const K: usize, const C: usize>(
    a: &Matrix<R, K>,
    b: &Matrix<K, C>,
) -> Matrix<R, C> {
    let mut out = [[0.0; C]; R];
    for (orow, arow) in out.iter_mut().zip(a) {
        for (aik, brow) in arow.iter().zip(b) {
            for (o, bkj) in orow.iter_mut().zip(brow) {
                *o += aik * bkj;
            }
        }
    }
    out
}

/// `a · x`.
pub fn mat_vec<const R: usize, const C: usize>(a: &Matrix<R, C>, x: &Vector<C>) -> Vector<R> {
    let mut out = [0.0; R];
    for (o, row) in out.iter_mut().zip(a) {
        *o = dot(row, x);
    }
    out
}

/// `xᵀ y`.
pub fn dot<const N: usize>(x: &Vector<N>, y: &Vector<N>) -> f64 {
    x.iter().zip(y).map(|(a, b)| a * b).sum()
}

/// `aᵀ`.
pub fn transpose<const R: usize, const C: usize>(a: &Matrix<R, C>) -> Matrix<C, R> {
    core::array::from_fn(|j| core::array::from_fn(|i| at2(a, i, j)))
}

/// `a + b`.
pub fn mat_add<const R: usize, const C: usize>(a: &Matrix<R, C>, b: &Matrix<R, C>) -> Matrix<R, C> {
    let mut out = *a;
    for (orow, brow) in out.iter_mut().zip(b) {
        for (o, x) in orow.iter_mut().zip(brow) {
            *o += x;
        }
    }
    out
}

/// `s · a`.
pub fn mat_scale<const R: usize, const C: usize>(a: &Matrix<R, C>, s: f64) -> Matrix<R, C> {
    let mut out = *a;
    for row in out.iter_mut() {
        for x in row.iter_mut() {
            *x *= s;
        }
    }
    out
}

/// `x + y`.
pub fn vec_add<const N: usize>(x: &Vector<N>, y: &Vector<N>) -> Vector<N> {
    core::array::from_fn(|i| at(x, i) + at(y, i))
}

/// `x − y`.
pub fn vec_sub<const N: usize>(x: &Vector<N>, y: &Vector<N>) -> Vector<N> {
    core::array::from_fn(|i| at(x, i) - at(y, i))
}

/// `s · x`.
pub fn vec_scale<const N: usize>(x: &Vector<N>, s: f64) -> Vector<N> {
    core::array::from_fn(|i| at(x, i) * s)
}

/// The 1-norm (largest absolute column sum).
pub fn norm_1<const R: usize, const C: usize>(a: &Matrix<R, C>) -> f64 {
    let mut sums = [0.0f64; C];
    for row in a {
        for (s, x) in sums.iter_mut().zip(row) {
            *s += libm::fabs(*x);
        }
    }
    sums.iter().fold(0.0, |m, &s| if s > m { s } else { m })
}

/// Largest absolute component.
pub fn norm_inf_vec<const N: usize>(x: &Vector<N>) -> f64 {
    x.iter().fold(0.0, |m, &v| {
        let a = libm::fabs(v);
        if a > m { a } else { m }
    })
}

/// `w += g·gᵀ`.
pub(crate) fn accumulate_outer<const S: usize>(w: &mut Matrix<S, S>, g: &Vector<S>) {
    for (row, gi) in w.iter_mut().zip(g.iter()) {
        for (x, gj) in row.iter_mut().zip(g.iter()) {
            *x += gi * gj;
        }
    }
}

/// Solves `a · x = b` by Gaussian elimination with partial pivoting.
///
/// Returns `x` and the ratio of the smallest to the largest pivot magnitude
/// (a cheap rank / conditioning indicator), or `None` when a pivot is zero
/// or the result is not finite.
pub fn solve<const N: usize>(mut a: Matrix<N, N>, mut b: Vector<N>) -> Option<(Vector<N>, f64)> {
    let mut min_pivot = f64::INFINITY;
    let mut max_pivot = 0.0f64;
    for k in 0..N {
        // Pivot: the row at or below k with the largest |a[i][k]|.
        let mut p = k;
        let mut best = -1.0;
        for (i, row) in a.iter().enumerate().skip(k) {
            let v = libm::fabs(at(row, k));
            if v > best {
                best = v;
                p = i;
            }
        }
        if best.is_nan() || best <= 0.0 || !best.is_finite() {
            return None;
        }
        min_pivot = min_pivot.min(best);
        max_pivot = max_pivot.max(best);
        a.swap(k, p);
        b.swap(k, p);
        let (upper, lower) = a.split_at_mut(k + 1);
        let (b_upper, b_lower) = b.split_at_mut(k + 1);
        let prow = upper.last()?;
        let pb = *b_upper.last()?;
        let pivot = at(prow, k);
        for (row, bi) in lower.iter_mut().zip(b_lower.iter_mut()) {
            let factor = at(row, k) / pivot;
            if factor != 0.0 {
                for (x, y) in row.iter_mut().zip(prow.iter()) {
                    *x -= factor * y;
                }
                *bi -= factor * pb;
            }
        }
    }
    let x = back_substitute(&a, &b);
    if x.iter().all(|v| v.is_finite()) {
        Some((x, min_pivot / max_pivot))
    } else {
        None
    }
}

/// Solves the symmetric positive (semi)definite system `w · x = d` after a
/// symmetric diagonal (Jacobi) scaling that gives `w` a unit diagonal, with
/// one step of iterative refinement. The scaling removes the huge spread of
/// magnitudes between state components of different units (rad, rad/s, A);
/// what remains is the genuine conditioning of the problem.
///
/// Returns `x` and the scaled pivot ratio (see [`solve`]); `None` when a
/// diagonal entry is not positive or the scaled matrix is singular.
pub fn spd_solve_scaled<const N: usize>(
    w: &Matrix<N, N>,
    d: &Vector<N>,
) -> Option<(Vector<N>, f64)> {
    let mut s = [0.0; N];
    for (i, si) in s.iter_mut().enumerate() {
        let wii = at2(w, i, i);
        if wii.is_nan() || wii <= 0.0 || !wii.is_finite() {
            return None;
        }
        *si = 1.0 / libm::sqrt(wii);
    }
    let ws: Matrix<N, N> =
        core::array::from_fn(|i| core::array::from_fn(|j| at2(w, i, j) * at(&s, i) * at(&s, j)));
    let ds: Vector<N> = core::array::from_fn(|i| at(d, i) * at(&s, i));
    let (mut y, ratio) = solve(ws, ds)?;
    // One refinement step on the scaled system.
    let r = vec_sub(&ds, &mat_vec(&ws, &y));
    if let Some((dy, _)) = solve(ws, r) {
        y = vec_add(&y, &dy);
    }
    let x = core::array::from_fn(|i| at(&y, i) * at(&s, i));
    Some((x, ratio))
}

/// Diagonal power-of-two balancing (Parlett–Reinsch): returns `d` such that
/// `D⁻¹ a D` has rows and columns of similar norms. Powers of two keep the
/// similarity exact in floating point.
fn balance<const N: usize>(a: &Matrix<N, N>) -> (Matrix<N, N>, Vector<N>) {
    const RADIX: f64 = 2.0;
    let mut b = *a;
    let mut d = [1.0; N];
    for _sweep in 0..64 {
        let mut done = true;
        for i in 0..N {
            let mut c = 0.0;
            let mut r = 0.0;
            for (j, row) in b.iter().enumerate() {
                if j != i {
                    c += libm::fabs(at(row, i));
                }
            }
            if let Some(row) = b.get(i) {
                for (j, v) in row.iter().enumerate() {
                    if j != i {
                        r += libm::fabs(*v);
                    }
                }
            }
            if c == 0.0 || r == 0.0 {
                continue;
            }
            let s = c + r;
            let mut f = 1.0;
            let mut cc = c;
            let g = r / RADIX;
            while cc < g && f < 1e150 {
                f *= RADIX;
                cc *= RADIX * RADIX;
            }
            let g = r * RADIX;
            while cc >= g && f > 1e-150 {
                f /= RADIX;
                cc /= RADIX * RADIX;
            }
            if (cc + r) / f < 0.95 * s {
                done = false;
                if let Some(di) = d.get_mut(i) {
                    *di *= f;
                }
                if let Some(row) = b.get_mut(i) {
                    for v in row.iter_mut() {
                        *v /= f;
                    }
                }
                for row in b.iter_mut() {
                    if let Some(v) = row.get_mut(i) {
                        *v *= f;
                    }
                }
            }
        }
        if done {
            break;
        }
    }
    (b, d)
}

/// `(e^{A t}, ∫₀ᵗ e^{A τ} dτ)` by balancing, scaling and squaring.
///
/// After balancing, `X = A·t/2^s` has 1-norm ≤ ½; both series are summed to
/// 20 terms (truncation < 1e-19 relative), then doubled `s` times with
/// `E(2h) = E(h)²` and `Φ(2h) = (I + E(h))·Φ(h)`.
pub fn expm_and_integral<const N: usize>(a: &Matrix<N, N>, t: f64) -> (Matrix<N, N>, Matrix<N, N>) {
    let (b, d) = balance(a);
    let x_full = mat_scale(&b, t);
    let mut norm = norm_1(&x_full);
    let mut squarings = 0u32;
    while norm > 0.5 && squarings < 200 {
        norm *= 0.5;
        squarings += 1;
    }
    let h = t / libm::pow(2.0, f64::from(squarings));
    let x = mat_scale(&b, h);
    let mut e = identity::<N>();
    let mut phi = mat_scale(&identity::<N>(), h);
    let mut term = identity::<N>();
    for k in 1..=20u32 {
        term = mat_scale(&mat_mul(&term, &x), 1.0 / f64::from(k));
        e = mat_add(&e, &term);
        phi = mat_add(&phi, &mat_scale(&term, h / f64::from(k + 1)));
    }
    for _ in 0..squarings {
        phi = mat_mul(&mat_add(&identity::<N>(), &e), &phi);
        e = mat_mul(&e, &e);
    }
    // Undo the balancing: M_ij = d_i · M'_ij / d_j.
    let unbalance = |m: &Matrix<N, N>| -> Matrix<N, N> {
        core::array::from_fn(|i| core::array::from_fn(|j| at(&d, i) * at2(m, i, j) / at(&d, j)))
    };
    (unbalance(&e), unbalance(&phi))
}

#[cfg(test)]
mod tests;
