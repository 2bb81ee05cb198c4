//! Near the double ring: curves I and II against the asymptotic formulas,
//! and the largest z* of the one-contact curve.

use crate::report::error::Result;
use crate::study::asymptotics::{curve_i, curve_ii, max_one_contact_z_star, one_contact_shifts};
use std::fmt::Write;

/// The section "Near the double ring: curves I and II".
pub(super) fn section() -> Result<String> {
    let mut s = String::new();
    writeln!(
        s,
        "\n## Near the double ring: curves I and II (Figure 13)\n"
    )?;
    s += &asymptotics_table()?;
    Ok(s)
}

/// The end shifts δ_I, δ_II along Δφ = 0.8 z*, against eqs. (6.15), (6.18).
fn asymptotics_table() -> Result<String> {
    let mut s = String::new();
    writeln!(
        s,
        "Along Δφ = 0.8 z* (N = 200): the end shifts δ_I, δ_II where the strands pass at c1, c2, against eqs. (6.15), (6.18) with exact coefficients ({:.4}, {:.4}).\n",
        crate::study::asymptotics::curve_i_first_order(),
        crate::study::asymptotics::curve_i_second_order()
    )?;
    writeln!(
        s,
        "| z* | Δφ | δ_I numerical | δ_I (6.15) | relative error | δ_II numerical | δ_II (6.18) | relative error |\n|---|---|---|---|---|---|---|---|"
    )?;
    for z in [0.08, 0.04, 0.02] {
        let dphi = 0.8 * z;
        let (d2, d1) = one_contact_shifts(200, z, dphi)?;
        let (a1, a2) = (curve_i(z, dphi), curve_ii(z, dphi));
        writeln!(
            s,
            "| {z} | {dphi:.3} | {d1:.6} | {a1:.6} | {:.2e} | {d2:.3e} | {a2:.3e} | {:.2e} |",
            (d1 - a1) / a1,
            (d2 - a2) / a2
        )?;
    }
    let zmax = max_one_contact_z_star(100, 0.001, 0.002)?;
    writeln!(
        s,
        "\nLargest z* of the one-contact curve at δ = 0.001 (N = 100, bisection to 0.002): {zmax:.4}; the paper's limit as δ → 0 is 0.223 (the self-contacting planar elastica)."
    )?;
    Ok(s)
}
