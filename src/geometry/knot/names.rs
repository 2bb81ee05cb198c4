//! Names for an Alexander polynomial: the tabled prime knots that have it
//! and the connected sums of tabled knots whose polynomials multiply to it
//! (Δ of a sum is the product). The polynomial does not determine the knot,
//! so every candidate is listed.

use super::table::KNOTS;
use std::sync::OnceLock;

/// Distinct polynomials of the table with the knots that have each, table order.
fn groups() -> &'static [(&'static [i64], Vec<&'static str>)] {
    static GROUPS: OnceLock<Vec<(&'static [i64], Vec<&'static str>)>> = OnceLock::new();
    GROUPS.get_or_init(|| {
        let mut out: Vec<(&'static [i64], Vec<&'static str>)> = Vec::new();
        for &(name, poly, _) in KNOTS {
            match out.iter_mut().find(|(p, _)| *p == poly) {
                Some((_, names)) => names.push(name),
                None => out.push((poly, vec![name])),
            }
        }
        out
    })
}

/// The quotient p / q of integer polynomials (lowest degree first), if exact.
fn divide(p: &[i64], q: &[i64]) -> Option<Vec<i64>> {
    if q.len() > p.len() {
        return None;
    }
    let mut rem: Vec<i128> = p.iter().map(|&x| x as i128).collect();
    let lead = *q.last()? as i128;
    let mut quot = vec![0i128; p.len() - q.len() + 1];
    for k in (0..quot.len()).rev() {
        let top = rem[k + q.len() - 1];
        if top % lead != 0 {
            return None;
        }
        let c = top / lead;
        quot[k] = c;
        for (j, &qj) in q.iter().enumerate() {
            rem[k + j] -= c * qj as i128;
        }
    }
    if rem.iter().any(|&r| r != 0) {
        return None;
    }
    quot.into_iter().map(|c| i64::try_from(c).ok()).collect()
}

/// At most this many sums are listed.
const MOST_SUMS: usize = 8;

fn sums(rest: &[i64], from: usize, chosen: &mut Vec<usize>, out: &mut Vec<Vec<usize>>) {
    if out.len() >= MOST_SUMS {
        return;
    }
    if rest == [1] {
        if chosen.len() >= 2 {
            out.push(chosen.clone());
        }
        return;
    }
    for (g, (poly, _)) in groups().iter().enumerate().skip(from.max(1)) {
        if let Some(q) = divide(rest, poly) {
            chosen.push(g);
            sums(&q, g, chosen, out);
            chosen.pop();
        }
    }
}

/// Every tabled knot with this (normalised) Alexander polynomial, then the
/// sums of tabled knots that have it, e.g. `["8_20", "3_1#3_1"]`; a factor
/// shared by several knots is written `(6_1|9_46)`. Empty past the table.
pub fn knot_names(alexander: &[i64]) -> Vec<String> {
    let groups = groups();
    let mut out: Vec<String> = groups
        .iter()
        .filter(|(p, _)| *p == alexander)
        .flat_map(|(_, names)| names.iter().map(|n| n.to_string()))
        .collect();
    if alexander == [1] {
        return out;
    }
    let mut found = Vec::new();
    sums(alexander, 1, &mut Vec::new(), &mut found);
    for sum in found {
        let parts: Vec<String> = sum
            .iter()
            .map(|&g| match groups[g].1.as_slice() {
                [one] => one.to_string(),
                many => format!("({})", many.join("|")),
            })
            .collect();
        out.push(parts.join("#"));
    }
    out
}

/// The Alexander polynomial of a tabled knot or of a sum of them written
/// with `#` (e.g. "3_1", "3_1#4_1"); None for a name not in the table.
pub fn alexander_of(name: &str) -> Option<Vec<i64>> {
    let mut poly = vec![1i64];
    for part in name.split('#') {
        let &(_, p, _) = KNOTS.iter().find(|(n, _, _)| *n == part.trim())?;
        let mut prod = vec![0i64; poly.len() + p.len() - 1];
        for (i, &x) in poly.iter().enumerate() {
            for (j, &y) in p.iter().enumerate() {
                prod[i + j] = prod[i + j].checked_add(x.checked_mul(y)?)?;
            }
        }
        poly = prod;
    }
    Some(poly)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn shared_polynomials_and_sums_are_all_named() {
        assert_eq!(knot_names(&[1, -1, 1]), vec!["3_1"]);
        assert_eq!(knot_names(&[-2, 5, -2]), vec!["6_1", "9_46"]);
        let granny = alexander_of("3_1#3_1").unwrap();
        assert_eq!(granny, vec![1, -2, 3, -2, 1]);
        let names = knot_names(&granny);
        assert!(
            names.contains(&"8_20".to_string()) && names.contains(&"3_1#3_1".to_string()),
            "{names:?}"
        );
        let mixed = alexander_of("3_1#4_1").unwrap();
        assert!(knot_names(&mixed).contains(&"3_1#4_1".to_string()));
        let with_shared = alexander_of("6_1#3_1").unwrap();
        assert!(
            knot_names(&with_shared).contains(&"3_1#(6_1|9_46)".to_string()),
            "{:?}",
            knot_names(&with_shared)
        );
        // T(2,13): Δ is the irreducible cyclotomic Φ₂₆, of span 12, past every tabled knot
        assert!(knot_names(&[1, -1, 1, -1, 1, -1, 1, -1, 1, -1, 1, -1, 1]).is_empty());
        assert_eq!(alexander_of("8_19").unwrap(), vec![1, -1, 0, 1, 0, -1, 1]);
        assert!(alexander_of("12a_1").is_none());
    }
}
