//! Exact determinants of integer matrix pencils A + tB as polynomials in t.
//!
//! Modulo each of several 62-bit primes (Montgomery arithmetic) the pencil is
//! written P(t) = P(c) (I + (t − c) M) with M = P(c)⁻¹B, and det(I + uM) is
//! read off the characteristic polynomial of M's Hessenberg form: O(n³) per
//! prime. The Hadamard bound on the coefficients fixes how many primes the
//! Chinese remainder theorem needs, so the integer answer is exact.

use std::sync::OnceLock;

/// The determinant's coefficients do not fit in 64 bits.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(super) struct Overflow;

/// Arithmetic modulo an odd prime p < 2⁶² in Montgomery form (R = 2⁶⁴).
struct Field {
    p: u64,
    /// −p⁻¹ mod 2⁶⁴.
    neg_inv: u64,
    /// R² mod p.
    r2: u64,
}

impl Field {
    fn new(p: u64) -> Field {
        // Newton's iteration doubles the correct low bits of p⁻¹ mod 2⁶⁴
        let mut inv: u64 = 1;
        for _ in 0..6 {
            inv = inv.wrapping_mul(2u64.wrapping_sub(p.wrapping_mul(inv)));
        }
        let r = ((1u128 << 64) % p as u128) as u64;
        let r2 = ((r as u128 * r as u128) % p as u128) as u64;
        Field {
            p,
            neg_inv: inv.wrapping_neg(),
            r2,
        }
    }

    #[inline]
    fn mul(&self, a: u64, b: u64) -> u64 {
        let t = a as u128 * b as u128;
        let m = (t as u64).wrapping_mul(self.neg_inv);
        // t + m p < p² + 2⁶⁴ p < 2¹²⁷ for p < 2⁶², and is divisible by 2⁶⁴
        let u = ((t + m as u128 * self.p as u128) >> 64) as u64;
        if u >= self.p { u - self.p } else { u }
    }

    #[inline]
    fn add(&self, a: u64, b: u64) -> u64 {
        let s = a + b;
        if s >= self.p { s - self.p } else { s }
    }

    #[inline]
    fn sub(&self, a: u64, b: u64) -> u64 {
        if a >= b { a - b } else { a + self.p - b }
    }

    fn of_i64(&self, x: i64) -> u64 {
        let r = x.rem_euclid(self.p as i64) as u64;
        self.mul(r, self.r2)
    }

    fn to_u64(&self, a: u64) -> u64 {
        self.mul(a, 1)
    }

    fn one(&self) -> u64 {
        self.of_i64(1)
    }

    fn pow(&self, mut a: u64, mut e: u64) -> u64 {
        let mut r = self.one();
        while e > 0 {
            if e & 1 == 1 {
                r = self.mul(r, a);
            }
            a = self.mul(a, a);
            e >>= 1;
        }
        r
    }

    fn inv(&self, a: u64) -> u64 {
        self.pow(a, self.p - 2)
    }
}

fn mul_mod(a: u64, b: u64, p: u64) -> u64 {
    ((a as u128 * b as u128) % p as u128) as u64
}

fn pow_mod(mut a: u64, mut e: u64, p: u64) -> u64 {
    let mut r = 1 % p;
    a %= p;
    while e > 0 {
        if e & 1 == 1 {
            r = mul_mod(r, a, p);
        }
        a = mul_mod(a, a, p);
        e >>= 1;
    }
    r
}

/// Deterministic Miller–Rabin for 64-bit n (these bases suffice below 3.3·10²⁴).
fn is_prime(n: u64) -> bool {
    const BASES: [u64; 12] = [2, 3, 5, 7, 11, 13, 17, 19, 23, 29, 31, 37];
    if n < 2 {
        return false;
    }
    for b in BASES {
        if n.is_multiple_of(b) {
            return n == b;
        }
    }
    let s = (n - 1).trailing_zeros();
    let d = (n - 1) >> s;
    'bases: for b in BASES {
        let mut x = pow_mod(b, d, n);
        if x == 1 || x == n - 1 {
            continue;
        }
        for _ in 1..s {
            x = mul_mod(x, x, n);
            if x == n - 1 {
                continue 'bases;
            }
        }
        return false;
    }
    true
}

/// The largest primes below 2⁶², descending.
fn primes() -> &'static [u64] {
    static PRIMES: OnceLock<Vec<u64>> = OnceLock::new();
    PRIMES.get_or_init(|| {
        let mut out = Vec::new();
        let mut n = (1u64 << 62) - 1;
        while out.len() < 64 {
            if is_prime(n) {
                out.push(n);
            }
            n -= 2;
        }
        out
    })
}

/// Coefficients (lowest degree first, length n + 1) of det(A + tB) for the
/// n×n integer matrices `a`, `b` (row-major).
pub(super) fn det_pencil(a: &[i64], b: &[i64], n: usize) -> Result<Vec<i64>, Overflow> {
    if n == 0 {
        return Ok(vec![1]);
    }
    // |coefficient| ≤ ‖coefficients‖₂ ≤ max over |t| = 1 of |det| ≤ ∏ row norms
    // (Parseval, then Hadamard), and |a + b t| ≤ |a| + |b| there
    let bits: f64 = (0..n)
        .map(|r| {
            let sq: f64 = (0..n)
                .map(|c| {
                    let m = (a[r * n + c].unsigned_abs() + b[r * n + c].unsigned_abs()) as f64;
                    m * m
                })
                .sum();
            0.5 * sq.max(1.0).log2()
        })
        .sum();
    let primes = primes();
    let mut count = 0;
    let mut covered = 0.0;
    // the product of the primes must exceed twice the bound (signs), with margin
    while covered < bits + 2.0 {
        if count == primes.len() {
            return Err(Overflow);
        }
        covered += (primes[count] as f64).log2();
        count += 1;
    }
    let residues: Vec<Vec<u64>> = primes[..count]
        .iter()
        .map(|&p| det_pencil_mod(&Field::new(p), a, b, n))
        .collect();
    (0..=n)
        .map(|k| {
            let r: Vec<u64> = residues.iter().map(|res| res[k]).collect();
            reconstruct(&r, &primes[..count]).ok_or(Overflow)
        })
        .collect()
}

/// det(A + tB) mod p, coefficients as plain residues.
fn det_pencil_mod(f: &Field, a: &[i64], b: &[i64], n: usize) -> Vec<u64> {
    let bm: Vec<u64> = b.iter().map(|&x| f.of_i64(x)).collect();
    // P(1) = A + B has det ±Δ(1) = ±1 for an Alexander matrix; other shifts
    // cover any pencil whose P(1) happens to be singular mod p
    for c in 1..=(n as i64 + 2) {
        let pc: Vec<u64> = a
            .iter()
            .zip(b)
            .map(|(&x, &y)| f.of_i64(x + c * y))
            .collect();
        let Some((det_c, m)) = solve(f, pc, &bm, n) else {
            continue;
        };
        let chi = charpoly(f, m, n);
        // det(I + uM) = Σ_j (−1)^j χ_{n−j} u^j
        let q: Vec<u64> = (0..=n)
            .map(|j| {
                let x = chi[n - j];
                if j % 2 == 1 { f.sub(0, x) } else { x }
            })
            .collect();
        // r(t) = q(t − c) by Horner, then times det P(c)
        let cm = f.of_i64(c);
        let mut r = vec![0u64; n + 1];
        for j in (0..=n).rev() {
            // r ← r·(t − c) + q_j
            for k in (0..n).rev() {
                let shifted = r[k];
                r[k + 1] = f.add(r[k + 1], shifted);
                r[k] = f.sub(0, f.mul(shifted, cm));
            }
            r[0] = f.add(r[0], q[j]);
        }
        return r.into_iter().map(|x| f.to_u64(f.mul(x, det_c))).collect();
    }
    // the pencil is singular for every shift tried: its determinant is 0
    vec![0; n + 1]
}

/// det P and P⁻¹B by Gauss–Jordan elimination on [P | B]; None if P is singular.
fn solve(f: &Field, mut pm: Vec<u64>, bm: &[u64], n: usize) -> Option<(u64, Vec<u64>)> {
    let mut x = bm.to_vec();
    let mut det = f.one();
    for col in 0..n {
        let piv = (col..n).find(|&r| pm[r * n + col] != 0)?;
        if piv != col {
            for k in 0..n {
                pm.swap(piv * n + k, col * n + k);
                x.swap(piv * n + k, col * n + k);
            }
            det = f.sub(0, det);
        }
        let d = pm[col * n + col];
        det = f.mul(det, d);
        let inv = f.inv(d);
        for k in 0..n {
            pm[col * n + k] = f.mul(pm[col * n + k], inv);
            x[col * n + k] = f.mul(x[col * n + k], inv);
        }
        for r in 0..n {
            let u = pm[r * n + col];
            if r == col || u == 0 {
                continue;
            }
            for k in col..n {
                pm[r * n + k] = f.sub(pm[r * n + k], f.mul(u, pm[col * n + k]));
            }
            for k in 0..n {
                x[r * n + k] = f.sub(x[r * n + k], f.mul(u, x[col * n + k]));
            }
        }
    }
    Some((det, x))
}

/// Characteristic polynomial det(xI − M), lowest degree first (length n + 1),
/// by reduction to upper Hessenberg form and its recurrence (Cohen, A Course
/// in Computational Algebraic Number Theory, Alg. 2.2.9).
fn charpoly(f: &Field, mut h: Vec<u64>, n: usize) -> Vec<u64> {
    for j in 0..n.saturating_sub(2) {
        let Some(i) = (j + 1..n).find(|&i| h[i * n + j] != 0) else {
            continue;
        };
        if i != j + 1 {
            for k in 0..n {
                h.swap(i * n + k, (j + 1) * n + k);
            }
            for k in 0..n {
                h.swap(k * n + i, k * n + j + 1);
            }
        }
        let inv = f.inv(h[(j + 1) * n + j]);
        for k in j + 2..n {
            let u = f.mul(h[k * n + j], inv);
            if u == 0 {
                continue;
            }
            // row k −= u row j+1, then column j+1 += u column k (a similarity)
            for l in j..n {
                h[k * n + l] = f.sub(h[k * n + l], f.mul(u, h[(j + 1) * n + l]));
            }
            for l in 0..n {
                h[l * n + j + 1] = f.add(h[l * n + j + 1], f.mul(u, h[l * n + k]));
            }
        }
    }
    // p_{m+1} = (x − h_mm) p_m − Σ_{i<m} h_im (∏_{k=i+1..m} h_{k,k−1}) p_i
    let mut polys: Vec<Vec<u64>> = vec![vec![f.one()]];
    for m in 0..n {
        let pm = &polys[m];
        let mut next = vec![0u64; m + 2];
        for (k, &c) in pm.iter().enumerate() {
            next[k + 1] = f.add(next[k + 1], c);
            next[k] = f.sub(next[k], f.mul(h[m * n + m], c));
        }
        let mut prod = f.one();
        for i in (0..m).rev() {
            prod = f.mul(prod, h[(i + 1) * n + i]);
            if prod == 0 {
                break;
            }
            let w = f.mul(h[i * n + m], prod);
            if w == 0 {
                continue;
            }
            for (k, &c) in polys[i].iter().enumerate() {
                next[k] = f.sub(next[k], f.mul(w, c));
            }
        }
        polys.push(next);
    }
    polys.pop().unwrap()
}

/// The integer in (−M/2, M/2), M = ∏ primes, with these residues, if it fits in i64.
fn reconstruct(residues: &[u64], primes: &[u64]) -> Option<i64> {
    let digits = |r: &[u64]| -> Vec<u64> {
        // Garner: v = d₀ + d₁p₀ + d₂p₀p₁ + …
        let mut d: Vec<u64> = Vec::with_capacity(r.len());
        for i in 0..r.len() {
            let p = primes[i];
            let mut x = r[i] % p;
            for (j, &dj) in d.iter().enumerate() {
                let inv = pow_mod(primes[j] % p, p - 2, p);
                x = mul_mod((x + p - dj % p) % p, inv, p);
            }
            d.push(x);
        }
        d
    };
    let d = digits(residues);
    // (M − 1)/2 has the digits (pᵢ − 1)/2: compare from the top
    let mut negative = false;
    for i in (0..d.len()).rev() {
        let half = (primes[i] - 1) / 2;
        if d[i] != half {
            negative = d[i] > half;
            break;
        }
    }
    let magnitude = if negative {
        let neg: Vec<u64> = residues
            .iter()
            .zip(primes)
            .map(|(&r, &p)| (p - r % p) % p)
            .collect();
        digits(&neg)
    } else {
        d
    };
    if magnitude.iter().skip(2).any(|&x| x != 0) {
        return None;
    }
    let v = magnitude[0] as u128
        + magnitude
            .get(1)
            .map_or(0, |&d1| d1 as u128 * primes[0] as u128);
    let v = i64::try_from(v).ok()?;
    Some(if negative { -v } else { v })
}

#[cfg(test)]
mod tests {
    use super::*;

    fn lcg(x: &mut u64) -> i64 {
        *x = x
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        ((*x >> 33) % 7) as i64 - 3
    }

    /// det of an integer matrix by fraction-free (Bareiss) elimination in i128.
    fn bareiss(mut m: Vec<i128>, n: usize) -> i128 {
        let mut sign = 1;
        let mut prev = 1i128;
        for k in 0..n {
            let Some(p) = (k..n).find(|&r| m[r * n + k] != 0) else {
                return 0;
            };
            if p != k {
                for c in 0..n {
                    m.swap(p * n + c, k * n + c);
                }
                sign = -sign;
            }
            for i in k + 1..n {
                for j in k + 1..n {
                    m[i * n + j] =
                        (m[i * n + j] * m[k * n + k] - m[i * n + k] * m[k * n + j]) / prev;
                }
            }
            prev = m[k * n + k];
        }
        sign * m[(n - 1) * n + n - 1]
    }

    #[test]
    fn pencil_determinant_matches_evaluation_at_integers() {
        let mut seed = 3;
        for n in 1..9 {
            for _ in 0..5 {
                let a: Vec<i64> = (0..n * n).map(|_| lcg(&mut seed)).collect();
                let b: Vec<i64> = (0..n * n).map(|_| lcg(&mut seed)).collect();
                let poly = det_pencil(&a, &b, n).unwrap();
                for t in -3i64..=3 {
                    let m: Vec<i128> = a
                        .iter()
                        .zip(&b)
                        .map(|(&x, &y)| (x + t * y) as i128)
                        .collect();
                    let direct = bareiss(m, n);
                    let horner = poly
                        .iter()
                        .rev()
                        .fold(0i128, |acc, &c| acc * t as i128 + c as i128);
                    assert_eq!(direct, horner, "n = {n}, t = {t}");
                }
            }
        }
    }

    #[test]
    fn negative_and_large_coefficients_are_reconstructed() {
        let p = primes();
        for v in [0i64, 1, -1, 1501, -1501, i64::MAX / 3, -(i64::MAX / 3)] {
            let r: Vec<u64> = p[..3]
                .iter()
                .map(|&q| v.rem_euclid(q as i64) as u64)
                .collect();
            assert_eq!(reconstruct(&r, &p[..3]), Some(v));
        }
        assert!(p.iter().all(|&q| q < 1 << 62 && is_prime(q)));
        assert!(!is_prime((1u64 << 61) + 1));
    }
}
