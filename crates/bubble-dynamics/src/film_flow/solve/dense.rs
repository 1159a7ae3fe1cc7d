//! A dense Cholesky factor of a level's matrix and its two triangular solves: the tests'
//! reference for the coarsest level's sparse solve (`sparse`), which it was until then.

use super::kernels::Stencil;
use super::layout::Layout;

/// The lower Cholesky factor of the coarsest level's matrix, column-major (`m[k·n + i]`
/// = `L[i][k]`), into `m` (a buffer kept from step to step: a fresh 74 kB one each step
/// was a malloc and free).
///
/// Column by column, each earlier column's part taken off all the rows at once: every
/// entry is the same sum in the same order as row by row, but where row by row each
/// entry was one chain of dependent subtractions (the core waiting on each), a column's
/// rows are independent lanes the compiler vectorises.
#[inline(always)]
pub(super) fn dense_cholesky(
    layout: &Layout,
    mass: &[f64],
    w: &Stencil<f64>,
    scale: f64,
    m: &mut Vec<f64>,
) {
    let n = layout.position.len();
    m.clear();
    m.resize(n * n, 0.0);
    // The matrix is symmetric: column-major is the same as row-major. Each cell's row
    // from its side weights (an edge's weight is the same seen from either cell).
    for (i, (&p, sides)) in layout.position.iter().zip(&layout.neighbour).enumerate() {
        m[i * n + i] = scale * mass[p as usize];
        let at = layout.side_weights(i);
        for (&j, (field, q)) in sides.iter().zip(at) {
            let wk = scale * w[field][q];
            m[i * n + i] += wk;
            m[i * n + j as usize] -= wk;
        }
    }
    for j in 0..n {
        let (done, rest) = m.split_at_mut(j * n);
        let column = &mut rest[j..n];
        for k in 0..j {
            let earlier = &done[k * n + j..][..n - j];
            let c = earlier[0];
            for (s, l) in column.iter_mut().zip(earlier) {
                *s -= l * c;
            }
        }
        let d = column[0].max(f64::MIN_POSITIVE).sqrt();
        column[0] = d;
        for s in &mut column[1..] {
            *s /= d;
        }
    }
}

/// Solves `L Lᵀ x = b` with [`dense_cholesky`]'s column-major factor `l`: forwards a
/// column at a time (each `x[i]` the same sum in the same order as row by row, the rows
/// independent lanes), backwards a row of `Lᵀ` (a column of `L`, contiguous) at a time.
#[inline(always)]
pub(super) fn dense_solve(l: &[f64], n: usize, b: &[f64], x: &mut [f64]) {
    let (l, x) = (&l[..n * n], &mut x[..n]);
    x.copy_from_slice(&b[..n]);
    for k in 0..n {
        let column = &l[k * n + k..][..n - k];
        let (solved, rest) = x.split_at_mut(k + 1);
        let xk = solved[k] / column[0];
        solved[k] = xk;
        for (s, lik) in rest.iter_mut().zip(&column[1..]) {
            *s -= lik * xk;
        }
    }
    for i in (0..n).rev() {
        let column = &l[i * n + i..][..n - i];
        let (head, solved) = x.split_at_mut(i + 1);
        let mut s = head[i];
        for (lki, xk) in column[1..].iter().zip(solved.iter()) {
            s -= lki * xk;
        }
        head[i] = s / column[0];
    }
}
