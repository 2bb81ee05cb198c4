//! Cell formatting shared by the tables: distances, observed orders and
//! error rows.

/// Euclidean distance between two 3-vectors.
pub(super) fn norm3(a: &[f64; 3], b: &[f64; 3]) -> f64 {
    a.iter()
        .zip(b)
        .map(|(x, y)| (x - y) * (x - y))
        .sum::<f64>()
        .sqrt()
}

/// Observed order log2(e_coarse / e_fine), "–" when an error is not positive.
pub(super) fn order(e_coarse: f64, e_fine: f64) -> String {
    if e_coarse > 0.0 && e_fine > 0.0 {
        format!("{:.2}", (e_coarse / e_fine).log2())
    } else {
        "–".into()
    }
}

/// Table cells "| value | order |" for a row of errors, the order taken
/// against the previous row (if any).
pub(super) fn error_cells(prev: Option<&[f64]>, cur: &[f64]) -> String {
    let mut line = String::new();
    for (c, e) in cur.iter().enumerate() {
        let p = prev.map_or(String::new(), |p| order(p[c], *e));
        line += &format!("| {e:.3e} | {p} ");
    }
    line + "|"
}
