//! What `knotrod verify` prints: a line per solution, each solution's details
//! (the s = 1 residual, the polish, the fit, the discrete rod at N, 2N, 4N
//! with its extrapolation against the continuum, the claims), as terminal
//! text or markdown.

use crate::study::verify::{
    BAR, ClaimOutcome, Disagreement, InputVerdict, ORDERS, Quantity, Setting, SolutionCheck,
    Stability, Verdict,
};
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
             residual {}{})",
            residual.map_or("—".into(), |r| format!("{r:.1e}")),
            c.input_error
                .as_deref()
                .map_or(String::new(), |e| format!("; {e}"))
        ),
    }
}

/// "; claims refuted: …; undecided: …" naming each claim not confirmed
/// (empty if every one is).
fn refuted(c: &SolutionCheck) -> String {
    let mut s = String::new();
    for (outcome, words) in [
        (ClaimOutcome::Refuted, "claims refuted"),
        (ClaimOutcome::Undecided, "claims undecided"),
    ] {
        let which: Vec<String> = c
            .claims
            .iter()
            .filter(|k| k.outcome == outcome)
            .map(|k| format!("{} (claimed {}, found {})", k.claim, k.claimed, k.found))
            .collect();
        if !which.is_empty() {
            let _ = write!(s, "; {words}: {}", which.join("; "));
        }
    }
    s
}

/// The count of negative directions, as far as the bars decide it: "2",
/// "1 to 2" (one bar straddles 0), "at least 4" (none computed is positive).
fn negative_count(s: &Stability) -> String {
    match (s.undecided, s.complete) {
        (0, true) => s.negative.to_string(),
        (u, true) => format!("{} to {}", s.negative, s.negative + u),
        (_, false) => format!("at least {}", s.negative),
    }
}

/// Stable, unstable with its negative count, or undecided.
fn inertia(c: &SolutionCheck) -> String {
    let Some(s) = &c.stability else {
        return "stability unknown".into();
    };
    let lowest = s.eigenvalues.first().map_or(String::new(), |e| {
        format!("lowest ω² {:.4} ± {:.1e}", e.extrapolated, e.bar())
    });
    match (s.stable(), s.negative()) {
        (Some(true), _) => "stable".to_string(),
        (Some(false), Some(k)) => format!(
            "unstable, {k} negative direction{}",
            if k == 1 { "" } else { "s" }
        ),
        (Some(false), None) => format!("unstable, {} negative directions", negative_count(s)),
        (None, _) => format!("stability undecided: {lowest} straddles 0"),
    }
}

/// A reason the methods disagree, in words.
fn disagreement(d: &Disagreement) -> String {
    let knot = |k: &Option<String>| k.clone().unwrap_or_else(|| "none".into());
    match d {
        Disagreement::Differs(q) => format!(
            "{} (the continuum's value lies outside the extrapolation's bar)",
            q.name()
        ),
        Disagreement::Knot {
            continuum,
            discrete,
        } => format!(
            "the knot type (continuum {}, discrete rod {})",
            knot(continuum),
            knot(discrete)
        ),
        Disagreement::Inertia {
            continuum,
            discrete,
        } => format!(
            "the negative directions (continuum {continuum} by conjugate points, discrete rod \
             {discrete})"
        ),
        Disagreement::KnotChangesWithN(k) => format!(
            "the discrete rod's knot type changes with N ({}): not one equilibrium",
            k.iter().map(knot).collect::<Vec<_>>().join(" / ")
        ),
        Disagreement::InertiaChangesWithN(n) => format!(
            "the discrete rod's negative count changes with N ({}) through an eigenvalue \
             that does not converge: not one equilibrium",
            n.iter()
                .map(|k| k.to_string())
                .collect::<Vec<_>>()
                .join(" / ")
        ),
        Disagreement::Order { quantity, order } => format!(
            "{}: observed order {order:.2}, outside [{}, {}]",
            quantity.name(),
            ORDERS.start(),
            ORDERS.end()
        ),
    }
}

/// The one-line verdict.
pub fn verdict_line(c: &SolutionCheck, all: &[SolutionCheck]) -> String {
    let name = |k: usize| all.get(k).map_or("?", |o| o.given.name.as_str());
    let twin = c.same_as.map_or(String::new(), |k| {
        format!("; the same equilibrium as row {} ({})", k + 1, name(k))
    });
    match &c.verdict {
        Verdict::Failed(why) => format!("FAILED: {why}"),
        Verdict::NotASolution => format!("NOT A SOLUTION: {}", input_line(c)),
        Verdict::DifferentEquilibrium { of, .. } => format!(
            "A DIFFERENT EQUILIBRIUM from row {} ({}) at the same parameters ({}; {} is {}); \
             both methods agree on it{twin}{}",
            of + 1,
            name(*of),
            inertia(c),
            name(*of),
            all.get(*of).map_or("?".into(), inertia),
            refuted(c)
        ),
        Verdict::MethodsDisagree { why } => {
            // the orders in one clause
            let orders: Vec<String> = why
                .iter()
                .filter_map(|d| match d {
                    Disagreement::Order { quantity, order } => {
                        Some(format!("{} {order:.2}", quantity.name()))
                    }
                    _ => None,
                })
                .collect();
            let mut reasons: Vec<String> = why
                .iter()
                .filter(|d| !matches!(d, Disagreement::Order { .. }))
                .map(disagreement)
                .collect();
            if !orders.is_empty() {
                reasons.push(format!(
                    "observed orders outside [{}, {}]: {} (N is not in the asymptotic range; \
                     the error estimates mean nothing)",
                    ORDERS.start(),
                    ORDERS.end(),
                    orders.join(", ")
                ));
            }
            format!("METHODS DISAGREE: {}{}", reasons.join("; "), refuted(c))
        }
        Verdict::ClaimsRefuted => format!("CLAIMS REFUTED{}{twin}", refuted(c)),
        Verdict::Confirmed => format!(
            "CONFIRMED by both methods ({}{}, knot {}{}){}{twin}{}",
            c.fold.as_ref().map_or(String::new(), |f| format!(
                "a fold in {}; beside its null direction: ",
                f.parameter.name()
            )),
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
            },
            refuted(c)
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
            c.stability.as_ref().map_or("—".into(), negative_count),
            verdict_line(c, checks)
        );
    }
    s
}

/// One solution in detail (markdown; it reads as plain text too).
pub fn details(c: &SolutionCheck, all: &[SolutionCheck]) -> String {
    let mut s = String::new();
    let _ = writeln!(s, "### {}. {} ({})\n", c.index + 1, c.given.name, c.law);
    if let Some(setting) = &c.setting {
        let _ = writeln!(s, "Parameters: {}.\n", clamp_parameters(setting));
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
    s.push_str(&fold_section(c));
    s.push_str(&discrete_tables(c));
    s.push_str(&estimates_table(c));
    if !c.claims.is_empty() {
        let _ = writeln!(s, "| claim | claimed | found | outcome |");
        let _ = writeln!(s, "|---|---|---|---|");
        for k in &c.claims {
            let _ = writeln!(
                s,
                "| {} | {} | {} | {} |",
                k.claim,
                k.claimed,
                k.found,
                match k.outcome {
                    ClaimOutcome::Confirmed => "confirmed",
                    ClaimOutcome::Refuted => "REFUTED",
                    ClaimOutcome::Undecided => "undecided",
                }
            );
        }
        let _ = writeln!(s);
    }
    if let Some(e) = &c.error {
        let _ = writeln!(s, "Error: {e}\n");
    }
    s
}

/// A claimed fold: the discrete rod's own folds at N, 2N, 4N beside the
/// continuum's and the claimed one.
fn fold_section(c: &SolutionCheck) -> String {
    let mut s = String::new();
    let Some(f) = &c.fold else {
        return s;
    };
    let name = f.parameter.name();
    let _ = writeln!(
        s,
        "**Fold:** claimed at {name} = {} (± {:.1e}, the claimant's location tolerance). At \
         each N the discrete rod is solved at its own fold: its branch, followed from an \
         equilibrium near the given shape, turns back in {name} there (located by bisection \
         in arclength); the eigenvalue that vanishes there is left out of its spectrum below. \
         The continuum's fold is the root of its shooting Jacobian's bordered determinant, \
         located from the discrete fold at 4N; its quantities below are the continuum \
         solution's there.\n",
        f.given, f.tolerance
    );
    let _ = writeln!(s, "| | {name} | vanishing ω² |");
    let _ = writeln!(s, "|---|---|---|");
    for (n, (v, w)) in c
        .setting
        .as_ref()
        .map_or([0; 3], |st| st.segments)
        .iter()
        .zip(f.discrete.iter().zip(&f.null_omega2))
    {
        let _ = writeln!(s, "| discrete fold, N = {n} | {v:.12} | {w:.2e} |");
    }
    if let Some(e) = c.estimate(Quantity::Fold) {
        let _ = writeln!(
            s,
            "| Richardson (2N, 4N) | {:.12} ± {:.1e} (order {:.2}) | |",
            e.extrapolated[0],
            e.error + e.model_error,
            e.order
        );
    }
    match (&f.continuum, &f.continuum_failure) {
        (Some((v, e)), _) => {
            let _ = writeln!(s, "| continuum fold | {v:.12} ± {e:.1e} | |");
        }
        (None, Some(why)) => {
            let _ = writeln!(s, "| continuum fold | not located: {why} | |");
        }
        (None, None) => {}
    }
    let _ = writeln!(s, "| claimed | {:.12} | |\n", f.given);
    s
}

/// The discrete rod at N, 2N, 4N and its extrapolated eigenvalues.
fn discrete_tables(c: &SolutionCheck) -> String {
    let mut s = String::new();
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
    if let Some(st) = c.stability.as_ref().filter(|st| !st.eigenvalues.is_empty()) {
        let _ = writeln!(
            s,
            "| ω²_k | at N, 2N, 4N | Richardson | discretisation error | stiffness error | order | sign (bar {BAR}× the errors) |"
        );
        let _ = writeln!(s, "|---|---|---|---|---|---|---|");
        for (k, e) in st.eigenvalues.iter().enumerate() {
            let _ = writeln!(
                s,
                "| {} | {:.4} / {:.4} / {:.4} | {:.6} | {:.1e} | {:.1e} | {:.2} | {:?} |",
                k + 1,
                e.values[0],
                e.values[1],
                e.values[2],
                e.extrapolated,
                e.error,
                e.model_error,
                e.order,
                e.sign()
            );
        }
        let _ = writeln!(
            s,
            "\nNegative directions of the extrapolated equilibrium: {} ({}).\n",
            negative_count(st),
            inertia(c)
        );
    }
    s
}

/// The extrapolated quantities against the continuum's.
fn estimates_table(c: &SolutionCheck) -> String {
    let mut s = String::new();
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
    s
}

/// z*, δ, φ/2π and every other clamp parameter that is not zero.
fn clamp_parameters(setting: &Setting) -> String {
    use crate::model::rod::Parameter;
    let shown: Vec<String> = setting
        .clamps
        .iter()
        .filter(|(p, v)| {
            matches!(p, Parameter::ZStar | Parameter::Delta | Parameter::Phi) || *v != 0.0
        })
        .map(|(p, v)| format!("{} = {v}", p.name()))
        .collect();
    shown.join(", ")
}

/// The setting of the first row that has one (rows may differ in their
/// clamps, each row's are in its details): law, K2, K3, the strip's ε, the
/// weight, S, N and the integrator's tolerance.
pub fn header(checks: &[SolutionCheck]) -> String {
    let Some((c, st)) = checks
        .iter()
        .find_map(|c| c.setting.as_ref().map(|s| (c, s)))
    else {
        return String::new();
    };
    let mut s = String::new();
    let _ = writeln!(s, "| setting | value |\n|---|---|");
    let _ = writeln!(s, "| law | {} |", c.law);
    let _ = writeln!(
        s,
        "| clamps (row {}) | {} |",
        c.index + 1,
        clamp_parameters(st)
    );
    let _ = writeln!(s, "| K2 = B22/B11, K3 = B33/B11 | {}, {} |", st.k2, st.k3);
    if let Some(e) = st.strip_epsilon {
        let _ = writeln!(s, "| strip regularisation ε | {e:e} |");
    }
    let _ = writeln!(
        s,
        "| weight w L³/B11 | ({}, {}, {}) |",
        st.weight[0], st.weight[1], st.weight[2]
    );
    let _ = writeln!(
        s,
        "| stretching stiffness S (the model error from S/10) | {:e} |",
        st.stiffness
    );
    let _ = writeln!(
        s,
        "| N, 2N, 4N | {}, {}, {} |",
        st.segments[0], st.segments[1], st.segments[2]
    );
    let _ = writeln!(s, "| integrator tolerance | {:e} |", st.tolerance);
    let _ = writeln!(
        s,
        "| rounding of an input | half a unit in its last printed digit |"
    );
    s
}

/// What each verdict means, and the rules behind them.
pub fn legend() -> String {
    format!(
        "- **CONFIRMED**: a solution (or one rounded within its printed digits); the discrete \
         rod converges to it (one equilibrium at N, 2N, 4N, observed orders in [{lo}, {hi}]), \
         every quantity agrees within its bar, and every claim holds.\n\
         - **CLAIMS REFUTED**: as confirmed, but a claim is not what was found, beyond its bar.\n\
         - **A DIFFERENT EQUILIBRIUM**: a solution at the same parameters (the resolved scene) \
         as an earlier row, polishing to another equilibrium than that row's; rows polishing to \
         the same one are grouped and judged alike.\n\
         - **METHODS DISAGREE**: the continuum lies outside the extrapolation's bar, the knot \
         types differ, or the discrete rod is not one converging equilibrium (its knot type or \
         inertia changes with N, or an observed order of a quantity resolved above the solves' \
         accuracy lies outside [{lo}, {hi}]); the reason is named.\n\
         - **NOT A SOLUTION**: the given unknowns miss their boundary conditions by more than \
         their rounding explains, or no solution lies near them.\n\
         - **FAILED**: the check itself could not be made (the reason is named).\n\n\
         Bars are {BAR} times the summed errors (discretisation, stretching stiffness and the \
         continuum's own). Stability and the count of negative directions come from the \
         extrapolated eigenvalues ω²_k: negative or positive when the bar excludes 0, \
         undecided when it straddles 0. A printed claim holds within one unit of its last \
         digit plus the bar.\n",
        lo = ORDERS.start(),
        hi = ORDERS.end()
    )
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
    let _ = writeln!(s, "## Setting\n\n{}", header(checks));
    let _ = writeln!(s, "## Verdicts\n\n{}", legend());
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
