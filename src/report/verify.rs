//! What `knotrod verify` prints: a line per solution, each solution's details
//! (the s = 1 residual, the polish, the fit, the discrete rod at N, 2N, 4N
//! with its extrapolation against the continuum, the claims), as terminal
//! text or markdown.

use crate::study::verify::{InputVerdict, Quantity, SolutionCheck, Verdict};
use std::fmt::Write;

fn vector(v: &[f64]) -> String {
    let parts: Vec<String> = v.iter().map(|x| format!("{x:.6}")).collect();
    if parts.len() == 1 {
        parts[0].clone()
    } else {
        format!("({})", parts.join(", "))
    }
}

/// Decimals of a number printed with half-unit `half` (as it was given).
fn printed_decimals(half: f64) -> usize {
    (-(2.0 * half).log10()).round().clamp(0.0, 17.0) as usize
}

/// What the input is, in words.
pub fn input_line(c: &SolutionCheck) -> String {
    let residual = c
        .end_residual
        .map(|r| r.iter().map(|x| x * x).sum::<f64>().sqrt());
    let units = c.rounding_units.unwrap_or(f64::NAN);
    match c.input {
        InputVerdict::Satisfies => format!(
            "satisfies its boundary conditions (s = 1 residual {:.1e})",
            residual.unwrap_or(f64::NAN)
        ),
        InputVerdict::Rounded => format!(
            "rounded: the solution at these parameters lies within its printed digits \
             ({units:.2} rounding units; s = 1 residual {:.1e})",
            residual.unwrap_or(f64::NAN)
        ),
        InputVerdict::RoundedParameter => match &c.fit {
            Some(f) => format!(
                "rounded: they solve the problem at {} = {:.6}, which rounds to the printed {}, \
                 to within their printed digits ({:.2} rounding units); at the printed value \
                 the s = 1 residual is {:.1e}",
                f.parameter.name(),
                f.value,
                f.given,
                f.rounding_units,
                residual.unwrap_or(f64::NAN)
            ),
            None => "rounded".into(),
        },
        InputVerdict::Misses => {
            let relative = match (c.moved, c.polished) {
                (Some(m), Some(p)) => {
                    let n = |v: &[f64]| v.iter().map(|x| x * x).sum::<f64>().sqrt();
                    n(&m) / n(&p)
                }
                _ => f64::NAN,
            };
            format!(
                "does not satisfy its boundary conditions: s = 1 residual {:.1e}; the solution \
                 at these parameters is {:.2e} away (relative), {units:.0} rounding units",
                residual.unwrap_or(f64::NAN),
                relative
            )
        }
        InputVerdict::NoSolutionNearby => format!(
            "does not satisfy its boundary conditions, and no solution lies near it (s = 1 \
             residual {})",
            residual.map_or("—".into(), |r| format!("{r:.1e}"))
        ),
    }
}

/// "; claims refuted: …" naming each refuted claim (empty if none is).
fn refuted(c: &SolutionCheck) -> String {
    let which: Vec<String> = c
        .claims
        .iter()
        .filter(|k| !k.confirmed)
        .map(|k| format!("{} (claimed {}, found {})", k.claim, k.claimed, k.found))
        .collect();
    if which.is_empty() {
        String::new()
    } else {
        format!("; claims refuted: {}", which.join("; "))
    }
}

/// The one-line verdict.
pub fn verdict_line(c: &SolutionCheck, all: &[SolutionCheck]) -> String {
    let inertia = |c: &SolutionCheck| match c.negative() {
        Some(0) => "stable".to_string(),
        Some(k) => format!(
            "unstable, {k} negative direction{}",
            if k == 1 { "" } else { "s" }
        ),
        None => "stability unknown".into(),
    };
    match &c.verdict {
        Verdict::Failed(why) => format!("FAILED: {why}"),
        Verdict::NotASolution => format!("NOT A SOLUTION: {}", input_line(c)),
        Verdict::DifferentEquilibrium { of } => format!(
            "A DIFFERENT EQUILIBRIUM from {} at the same parameters ({}; {} is {}); both methods \
             agree on it{}",
            all.get(*of).map_or("?", |o| o.given.name.as_str()),
            inertia(c),
            all.get(*of).map_or("?", |o| o.given.name.as_str()),
            all.get(*of).map_or("?".into(), inertia),
            refuted(c)
        ),
        Verdict::MethodsDisagree => {
            let which: Vec<&str> = c
                .estimates
                .iter()
                .filter(|e| e.agrees == Some(false))
                .map(|e| e.quantity.name())
                .collect();
            format!(
                "METHODS DISAGREE on {} (the discrete rod does not converge to the continuum \
                 solution within its error estimate)",
                if which.is_empty() {
                    "the knot type".to_string()
                } else {
                    which.join(", ")
                }
            )
        }
        Verdict::ClaimsRefuted => format!("CLAIMS REFUTED{}", refuted(c)),
        Verdict::Confirmed => format!(
            "CONFIRMED by both methods ({}, knot {}{}){}",
            inertia(c),
            c.continuum_knot.as_deref().unwrap_or("none"),
            if c.claims.is_empty() {
                String::new()
            } else {
                format!(", {} claims", c.claims.len())
            },
            match (&c.input, &c.fit) {
                (InputVerdict::RoundedParameter, Some(f)) => format!(
                    "; the unknowns belong to {} = {:.6} (printed {})",
                    f.parameter.name(),
                    f.value,
                    f.given
                ),
                (InputVerdict::Rounded, _) => "; the unknowns are rounded".into(),
                _ => String::new(),
            }
        ),
    }
}

/// The summary table: one row per solution.
pub fn summary(checks: &[SolutionCheck]) -> String {
    let mut s = String::new();
    let _ = writeln!(
        s,
        "{:>4}  {:<24} {:>10} {:>9} {:>10} {:>10} {:>9}  verdict",
        "#", "solution", "residual", "rounding", "Δn(0) rel", "Δm(0) rel", "neg"
    );
    for c in checks {
        let residual = c
            .end_residual
            .map(|r| r.iter().map(|x| x * x).sum::<f64>().sqrt());
        let rel = |q: Quantity| {
            c.estimate(q)
                .and_then(|e| e.relative)
                .map_or("—".into(), |r| format!("{r:.1e}"))
        };
        let _ = writeln!(
            s,
            "{:>4}  {:<24} {:>10} {:>9} {:>10} {:>10} {:>9}  {}",
            c.index + 1,
            c.given.name.chars().take(24).collect::<String>(),
            residual.map_or("—".into(), |r| format!("{r:.1e}")),
            c.rounding_units.map_or("—".into(), |u| format!("{u:.1}")),
            rel(Quantity::Force),
            rel(Quantity::Moment),
            c.negative().map_or("—".into(), |k| k.to_string()),
            verdict_line(c, checks)
        );
    }
    s
}

/// One solution in detail (markdown; it reads as plain text too).
pub fn details(c: &SolutionCheck, all: &[SolutionCheck]) -> String {
    let mut s = String::new();
    let _ = writeln!(s, "### {}. {} ({})\n", c.index + 1, c.given.name, c.law);
    if !c.given.parameters.is_empty() {
        let p: Vec<String> = c
            .given
            .parameters
            .iter()
            .map(|(p, v)| format!("{} = {v}", p.name()))
            .collect();
        let _ = writeln!(s, "Parameters: {}.\n", p.join(", "));
    }
    let _ = writeln!(s, "**Verdict:** {}\n", verdict_line(c, all));
    let _ = writeln!(s, "**Input:** {}\n", input_line(c));
    if let Some(r) = c.end_residual {
        let _ = writeln!(
            s,
            "s = 1 residual from the given unknowns (r − r*, d3 off the clamp's tangent ×2, \
             angle of d1): ({:.2e}, {:.2e}, {:.2e}, {:.2e}, {:.2e}, {:.2e})\n",
            r[0], r[1], r[2], r[3], r[4], r[5]
        );
    }
    if let (Some(p), Some(m)) = (c.polished, c.moved) {
        let _ = writeln!(s, "| unknown | given | polished | moved | rounding |");
        let _ = writeln!(s, "|---|---|---|---|---|");
        let names = if c.law.contains("strip") {
            ["n1(0)", "n2(0)", "n3(0)", "u1(0)", "m2(0)", "u3(0)"]
        } else {
            ["n1(0)", "n2(0)", "n3(0)", "m1(0)", "m2(0)", "m3(0)"]
        };
        for k in 0..6 {
            let _ = writeln!(
                s,
                "| {} | {:.*} | {:.9} | {:+.2e} | {:.0e} |",
                names[k],
                printed_decimals(c.given.rounding[k]),
                c.given.unknowns[k],
                p[k],
                m[k],
                c.given.rounding[k]
            );
        }
        let _ = writeln!(
            s,
            "\nNewton shooting: {} iterations.\n",
            c.polish_iterations
        );
    }
    if let Some(f) = &c.fit {
        let _ = writeln!(
            s,
            "**Fit:** the given unknowns belong to {} = {:.9} (given {}): there the solution \
             lies {:.2} rounding units from them.\n",
            f.parameter.name(),
            f.value,
            f.given,
            f.rounding_units
        );
    }
    if let Some(e) = &c.fit_error {
        let _ = writeln!(s, "Fit failed: {e}\n");
    }
    if !c.der.is_empty() {
        let _ = writeln!(
            s,
            "| N | n(0) | m(0) | Tw | energy | link | lowest ω² | negative | walled | knot | Newton |"
        );
        let _ = writeln!(s, "|---|---|---|---|---|---|---|---|---|---|---|");
        for d in &c.der {
            let _ = writeln!(
                s,
                "| {} | {} | {} | {:.7} | {:.7} | {:.6} | {} | {} | {} | {} | {} |",
                d.segments,
                vector(&d.n0),
                vector(&d.m0),
                d.twist,
                d.energy,
                d.link,
                d.lowest_omega2.map_or("—".into(), |w| format!("{w:.4}")),
                d.negative,
                d.walled,
                d.knot.as_deref().unwrap_or("none"),
                d.iterations
            );
        }
        let _ = writeln!(s);
    }
    if !c.estimates.is_empty() {
        let _ = writeln!(
            s,
            "| quantity | Richardson (2N, 4N) | discretisation error | stiffness error | order | continuum | its error | difference | relative | in errors | agrees |"
        );
        let _ = writeln!(s, "|---|---|---|---|---|---|---|---|---|---|---|");
        for e in &c.estimates {
            let _ = writeln!(
                s,
                "| {} | {} | {:.1e} | {:.1e} | {:.2} | {} | {} | {} | {} | {} | {} |",
                e.quantity.name(),
                vector(&e.extrapolated),
                e.error,
                e.model_error,
                e.order,
                e.continuum.as_deref().map_or("—".into(), vector),
                e.continuum_error.map_or("—".into(), |d| format!("{d:.1e}")),
                e.difference.map_or("—".into(), |d| format!("{d:.1e}")),
                e.relative.map_or("—".into(), |d| format!("{d:.1e}")),
                e.sigmas.map_or("—".into(), |d| format!("{d:.2}")),
                e.agrees.map_or("—", |a| if a { "yes" } else { "NO" }),
            );
        }
        let _ = writeln!(
            s,
            "\nKnot of the continuum curve's ray closure: {}.\n",
            c.continuum_knot.as_deref().unwrap_or("none")
        );
    }
    if !c.claims.is_empty() {
        let _ = writeln!(s, "| claim | claimed | found | confirmed |");
        let _ = writeln!(s, "|---|---|---|---|");
        for k in &c.claims {
            let _ = writeln!(
                s,
                "| {} | {} | {} | {} |",
                k.claim,
                k.claimed,
                k.found,
                if k.confirmed { "yes" } else { "NO" }
            );
        }
        let _ = writeln!(s);
    }
    if let Some(e) = &c.error {
        let _ = writeln!(s, "Error: {e}\n");
    }
    s
}

/// The markdown report: how it was made, the summary, each solution, and the
/// convergence plot if one was drawn.
pub fn markdown(
    command: &str,
    file: &str,
    checks: &[SolutionCheck],
    segments: [usize; 3],
    plot: Option<&str>,
) -> String {
    let mut s = String::new();
    let _ = writeln!(s, "# knotrod verify: {file}\n");
    let _ = writeln!(s, "Command: `{command}`.\n");
    let _ = writeln!(
        s,
        "Each solution is checked two ways: the continuum equations integrated adaptively \
         (Dormand–Prince 8(5,3), tolerance 1e-12) from the given unknowns and polished by \
         Newton shooting; and the discrete elastic rod solved from that shape at N = {}, {}, {} \
         and Richardson-extrapolated, each quantity with the error estimate |R(N, 2N) − R(2N, \
         4N)| and the stretching penalty's model error |q(S) − q(S/10)| / 9 at N. A quantity \
         agrees when the two methods differ by less than three times the summed errors. A \
         printed claim is confirmed within one unit of its last digit plus those errors.\n",
        segments[0], segments[1], segments[2]
    );
    let _ = writeln!(s, "## Summary\n\n```\n{}```\n", summary(checks));
    if let Some(p) = plot {
        let _ = writeln!(
            s,
            "![convergence of the discrete rod to the continuum solution]({p})\n"
        );
    }
    let _ = writeln!(s, "## Solutions\n");
    for c in checks {
        s += &details(c, checks);
    }
    s
}
