//! Dense 4×4 linear algebra for the Eq. 13 fit: Cholesky factorisation of the normal
//! equations, solves and the inverse that gives the covariance.

/// A symmetric 4×4 matrix; the fit uses its leading k×k block (k free parameters).
pub(in crate::analysis) type Mat = [[f64; 4]; 4];

/// Cholesky factor of the leading k×k block; `None` if it is not positive
/// definite or a parameter is (nearly) a linear combination of the others.
fn cholesky(a: &Mat, k: usize) -> Option<Mat> {
    let mut l = [[0.0; 4]; 4];
    for i in 0..k {
        for j in 0..=i {
            let s = a[i][j] - (0..j).map(|m| l[i][m] * l[j][m]).sum::<f64>();
            if i == j {
                if s.is_nan() || s <= 1e-13 * a[i][i] || s <= 0.0 {
                    return None;
                }
                l[i][i] = s.sqrt();
            } else {
                l[i][j] = s / l[j][j];
            }
        }
    }
    Some(l)
}

fn solve_with(l: &Mat, b: &[f64; 4], k: usize) -> [f64; 4] {
    let mut y = [0.0; 4];
    for i in 0..k {
        y[i] = (b[i] - (0..i).map(|m| l[i][m] * y[m]).sum::<f64>()) / l[i][i];
    }
    let mut x = [0.0; 4];
    for i in (0..k).rev() {
        x[i] = (y[i] - (i + 1..k).map(|m| l[m][i] * x[m]).sum::<f64>()) / l[i][i];
    }
    x
}

pub(in crate::analysis) fn solve_spd(a: &Mat, b: &[f64; 4], k: usize) -> Option<Vec<f64>> {
    let l = cholesky(a, k)?;
    Some(solve_with(&l, b, k)[..k].to_vec())
}

pub(in crate::analysis) fn invert_spd(a: &Mat, k: usize) -> Option<Mat> {
    let l = cholesky(a, k)?;
    let mut inv = [[0.0; 4]; 4];
    for c in 0..k {
        let mut e = [0.0; 4];
        e[c] = 1.0;
        let col = solve_with(&l, &e, k);
        for (row, v) in inv.iter_mut().zip(col).take(k) {
            row[c] = v;
        }
    }
    Some(inv)
}
