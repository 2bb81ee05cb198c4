//! `knotrod verify`: someone's shooting solutions checked by two independent
//! methods. For each solution (its scene parameters and six shooting
//! unknowns at s = 0):
//! 1. the continuum equations are integrated adaptively from the given
//!    unknowns (the s = 1 residual, component by component), polished by
//!    Newton shooting (how far the unknowns moved, in units of their printed
//!    rounding), and, if asked, fitted in one scene parameter (the value whose
//!    solution lies closest to the given unknowns);
//! 2. the discrete rod is solved from the polished shape at N, 2N and 4N and
//!    Richardson-extrapolated, each quantity with an error estimate;
//! 3. the two are compared quantity by quantity, and the author's claims
//!    (stability, Tw, link, energy, knot, walls) against both.
//!
//! Rows run in parallel; each row's result depends on that row only, so the
//! results are the same for any thread count.

use crate::analysis::equilibrium::Equilibrium;
use crate::geometry::closure::{closure_knot_along, ray_closure};
use crate::geometry::writhe::writhe_closed;
use crate::model::continuum::{Continuum, Polished, Unknowns};
use crate::model::rod::{Law, Parameter};
use crate::scene::{InitialShape, Scene};
use crate::study::error::{Context, Result, StudyError, describe, fail};
use crate::study::start::equilibrium_near_start;
use serde::{Deserialize, Serialize};

/// A number as printed: its value and half a unit in its last digit.
#[derive(Clone, Copy, Debug, Serialize, Deserialize, PartialEq)]
pub struct Printed {
    /// The value.
    pub value: f64,
    /// Half a unit in its last printed digit.
    pub half_unit: f64,
}

/// What an author claims of a solution (each optional).
#[derive(Clone, Debug, Default, Serialize, Deserialize, PartialEq)]
pub struct Claims {
    /// Stable (no negative direction of the second variation).
    pub stable: Option<bool>,
    /// Lowest ω² (eigenvalue of the second variation).
    pub lowest_omega2: Option<Printed>,
    /// Tw = (1/2π) ∫ u3 ds.
    pub twist: Option<Printed>,
    /// Tw + Wr of the ray closure.
    pub link: Option<Printed>,
    /// Between the walls z = 0 and z = z*.
    pub walled: Option<bool>,
    /// Knot type of the ray closure, e.g. "3_1".
    pub knot: Option<String>,
    /// Energy ∫ (W − w g·r) ds.
    pub energy: Option<Printed>,
}

/// One solution to verify, as given.
#[derive(Clone, Debug, Serialize, Deserialize, PartialEq)]
pub struct Solution {
    /// Its name (the row's, or "row k").
    pub name: String,
    /// Scene parameters set for it (on top of the base scene).
    pub parameters: Vec<(Parameter, f64)>,
    /// Half a unit in the last printed digit of each parameter.
    pub parameter_rounding: Vec<f64>,
    /// The six shooting unknowns: n(0), m(0) for a rod; n(0), u1(0), m2(0),
    /// u3(0) for a strip (material frame at s = 0).
    pub unknowns: [f64; 6],
    /// Half a unit in the last printed digit of each unknown (what rounding
    /// can explain).
    pub rounding: [f64; 6],
    /// The author's claims.
    pub claims: Claims,
}

/// How verify runs.
#[derive(Clone, Debug)]
pub struct VerifyOptions {
    /// The three resolutions N, 2N, 4N.
    pub segments: [usize; 3],
    /// Fit this parameter to the given unknowns.
    pub fit: Option<Parameter>,
    /// Stretching stiffness of the discrete rod (its inextensible limit is
    /// the continuum's; the model error is O(1/stiffness)).
    pub stretching_stiffness: f64,
    /// Tolerance of the adaptive integrator.
    pub tolerance: f64,
}

impl Default for VerifyOptions {
    fn default() -> Self {
        VerifyOptions {
            segments: [100, 200, 400],
            fit: None,
            stretching_stiffness: 1e7,
            tolerance: 1e-12,
        }
    }
}

/// What the given unknowns are, judged by the continuum alone.
#[derive(Clone, Debug, Serialize, Deserialize, PartialEq)]
pub enum InputVerdict {
    /// They satisfy the s = 1 conditions to the integrator's accuracy.
    Satisfies,
    /// The solution at these parameters lies within their printed rounding.
    Rounded,
    /// The solution at the fitted parameter value, which rounds to the
    /// printed one, lies within their printed rounding.
    RoundedParameter,
    /// The solution at these parameters is farther than rounding explains:
    /// they do not satisfy their boundary conditions.
    Misses,
    /// Newton shooting found no solution near them.
    NoSolutionNearby,
}

/// The parameter value whose solution lies closest to the given unknowns.
#[derive(Clone, Debug, Serialize, Deserialize, PartialEq)]
pub struct Fit {
    /// The parameter.
    pub parameter: Parameter,
    /// Its given value.
    pub given: f64,
    /// The fitted value.
    pub value: f64,
    /// The polished unknowns there.
    pub unknowns: [f64; 6],
    /// Largest |polished − given| in rounding units there.
    pub rounding_units: f64,
}

/// The discrete rod at one resolution.
#[derive(Clone, Debug, Serialize, Deserialize, PartialEq)]
pub struct DerRow {
    /// N.
    pub segments: usize,
    /// n(0) (clamp reaction, s = 0 material frame).
    pub n0: [f64; 3],
    /// m(0).
    pub m0: [f64; 3],
    /// Tw.
    pub twist: f64,
    /// Energy.
    pub energy: f64,
    /// Tw + Wr.
    pub link: f64,
    /// Lowest ω².
    pub lowest_omega2: Option<f64>,
    /// Negative directions of the second variation.
    pub negative: usize,
    /// Walled.
    pub walled: bool,
    /// Knot name of the ray closure.
    pub knot: Option<String>,
    /// Newton iterations.
    pub iterations: usize,
}

/// A compared quantity.
#[derive(Clone, Copy, Debug, Serialize, Deserialize, PartialEq, Eq)]
pub enum Quantity {
    /// n(0).
    Force,
    /// m(0).
    Moment,
    /// Tw.
    Twist,
    /// Energy.
    Energy,
    /// Tw + Wr.
    Link,
    /// Lowest ω².
    LowestOmega2,
}

impl Quantity {
    /// Name in tables.
    pub fn name(self) -> &'static str {
        match self {
            Quantity::Force => "n(0)",
            Quantity::Moment => "m(0)",
            Quantity::Twist => "Tw",
            Quantity::Energy => "energy",
            Quantity::Link => "link",
            Quantity::LowestOmega2 => "lowest ω²",
        }
    }
}

/// A quantity's Richardson extrapolation, and the continuum's value beside it.
#[derive(Clone, Debug, Serialize, Deserialize, PartialEq)]
pub struct Estimate {
    /// Which.
    pub quantity: Quantity,
    /// At N, 2N, 4N (components).
    pub values: [Vec<f64>; 3],
    /// Observed order log2(|q_N − q_2N| / |q_2N − q_4N|).
    pub order: f64,
    /// Richardson value (4 q_4N − q_2N) / 3.
    pub extrapolated: Vec<f64>,
    /// Its discretisation error estimate: |R(N, 2N) − R(2N, 4N)| (norm).
    pub error: f64,
    /// The stretching penalty's model error at N (it hardly depends on N): |q(S) − q(S/10)| / 9
    /// (the error is O(1/S); the continuum is inextensible).
    pub model_error: f64,
    /// The continuum value's own error (the writhe's sampling, for the link).
    pub continuum_error: Option<f64>,
    /// The continuum's value (None for ω²).
    pub continuum: Option<Vec<f64>>,
    /// |continuum − extrapolated| (norm).
    pub difference: Option<f64>,
    /// That difference relative to |extrapolated|.
    pub relative: Option<f64>,
    /// The difference in units of the summed error estimates.
    pub sigmas: Option<f64>,
    /// Agrees within three times the sum of the errors (or to 1e-9 relative).
    pub agrees: Option<bool>,
}

/// A claim against what was found.
#[derive(Clone, Debug, Serialize, Deserialize, PartialEq)]
pub struct ClaimCheck {
    /// The claim's name.
    pub claim: String,
    /// Claimed.
    pub claimed: String,
    /// Found.
    pub found: String,
    /// Confirmed.
    pub confirmed: bool,
}

/// The one-line verdict of a solution.
#[derive(Clone, Debug, Serialize, Deserialize, PartialEq)]
pub enum Verdict {
    /// The check could not be made (why).
    Failed(String),
    /// No solution of these boundary conditions lies near the given unknowns.
    NotASolution,
    /// A solution of the same parameters as another row, but another one.
    DifferentEquilibrium {
        /// The other row (index).
        of: usize,
    },
    /// The discrete rod does not converge to the continuum solution.
    MethodsDisagree,
    /// The claims are not what was found.
    ClaimsRefuted,
    /// Confirmed by both methods, with the claims.
    Confirmed,
}

/// Everything verify found about one solution.
#[derive(Clone, Debug, Serialize, Deserialize, PartialEq)]
pub struct SolutionCheck {
    /// Row index.
    pub index: usize,
    /// The solution as given.
    pub given: Solution,
    /// Law of the model ("Kirchhoff rod", "elastic strip", …).
    pub law: String,
    /// The s = 1 residual of the given unknowns, component by component.
    pub end_residual: Option<[f64; 6]>,
    /// Newton shooting from them, at the given parameters.
    pub polished: Option<[f64; 6]>,
    /// Newton iterations of the polish.
    pub polish_iterations: usize,
    /// polished − given.
    pub moved: Option<[f64; 6]>,
    /// Largest |moved| in rounding units.
    pub rounding_units: Option<f64>,
    /// The continuum's judgement of the input.
    pub input: InputVerdict,
    /// The fitted parameter, if asked.
    pub fit: Option<Fit>,
    /// Why the fit failed, if it did.
    pub fit_error: Option<String>,
    /// Knot of the continuum curve's ray closure.
    pub continuum_knot: Option<String>,
    /// The discrete rod at N, 2N, 4N.
    pub der: Vec<DerRow>,
    /// The extrapolated quantities against the continuum.
    pub estimates: Vec<Estimate>,
    /// The claims checked.
    pub claims: Vec<ClaimCheck>,
    /// The verdict.
    pub verdict: Verdict,
    /// Why a step failed.
    pub error: Option<String>,
}

impl SolutionCheck {
    /// The estimate of a quantity.
    pub fn estimate(&self, q: Quantity) -> Option<&Estimate> {
        self.estimates.iter().find(|e| e.quantity == q)
    }

    /// Negative directions at the finest N.
    pub fn negative(&self) -> Option<usize> {
        self.der.last().map(|d| d.negative)
    }
}

/// The base scene with a solution's parameters set and its unknowns as the
/// shooting start (validated: a bad parameter names its field).
pub fn scene_of(base: &Scene, s: &Solution, options: &VerifyOptions) -> Result<Scene> {
    let mut scene = base.clone();
    for &(p, v) in &s.parameters {
        scene.set(p, v);
    }
    set_unknowns(&mut scene, &s.unknowns);
    scene.model.stretching_stiffness = Some(options.stretching_stiffness);
    scene.initial.shape = InitialShape::Shooting;
    scene.initial.refine = false;
    // a start's own steps (the double ring's) are not the integration's
    scene.initial.steps = None;
    scene.initial.from_recording = None;
    scene.initial.file = None;
    scene.initial.state = None;
    scene.stability.eigenvalues = scene.stability.eigenvalues.max(1);
    scene.validate()?;
    Ok(scene)
}

fn set_unknowns(scene: &mut Scene, p: &[f64; 6]) {
    scene.initial.n0 = Some([p[0], p[1], p[2]]);
    if matches!(scene.rod_model(None).law, Law::Strip { .. }) {
        (scene.initial.u1_0, scene.initial.m2_0, scene.initial.u3_0) =
            (Some(p[3]), Some(p[4]), Some(p[5]));
        scene.initial.m0 = None;
    } else {
        scene.initial.m0 = Some([p[3], p[4], p[5]]);
    }
}

fn continuum_of(scene: &Scene, options: &VerifyOptions) -> Result<Continuum> {
    Ok(Continuum::of(
        &scene.rod_model(None),
        scene.clamps(),
        options.tolerance,
    )?)
}

fn units(moved: &Unknowns, rounding: &[f64; 6]) -> f64 {
    (0..6)
        .map(|k| moved[k].abs() / rounding[k].max(f64::MIN_POSITIVE))
        .fold(0.0, f64::max)
}

/// The s = 1 residual below which given unknowns satisfy their conditions.
const SATISFIED: f64 = 1e-8;
/// Rows whose polished unknowns differ by more than this (relative) at the
/// same parameters are different equilibria.
const SAME_EQUILIBRIUM: f64 = 1e-6;
/// Points of the continuum curve for its writhe and knot type.
const CURVE_SAMPLES: usize = 1201;

/// Verify one solution against `base`.
pub fn verify_solution(
    base: &Scene,
    index: usize,
    s: &Solution,
    options: &VerifyOptions,
) -> SolutionCheck {
    let mut check = SolutionCheck {
        index,
        given: s.clone(),
        law: String::new(),
        end_residual: None,
        polished: None,
        polish_iterations: 0,
        moved: None,
        rounding_units: None,
        input: InputVerdict::NoSolutionNearby,
        fit: None,
        fit_error: None,
        continuum_knot: None,
        der: vec![],
        estimates: vec![],
        claims: vec![],
        verdict: Verdict::Failed(String::new()),
        error: None,
    };
    if let Err(e) = run(base, s, options, &mut check) {
        let why = describe(&e);
        check.error = Some(why.clone());
        check.verdict = Verdict::Failed(why);
        return check;
    }
    check.verdict = verdict_of(&check);
    check
}

fn run(
    base: &Scene,
    s: &Solution,
    options: &VerifyOptions,
    check: &mut SolutionCheck,
) -> Result<()> {
    let scene = scene_of(base, s, options).context("the solution's scene")?;
    let model = scene.rod_model(None);
    check.law = model.law.name().to_string();
    let continuum = continuum_of(&scene, options)?;
    let given = Unknowns::from(s.unknowns);
    let at_given = continuum
        .solve(&given, 0)
        .context("integrating from the given unknowns")?;
    check.end_residual = Some(at_given.end_residual.into());
    let polished = match continuum.polish(&given) {
        Ok(p) => p,
        Err(e) => {
            check.input = InputVerdict::NoSolutionNearby;
            check.error = Some(format!("polishing by Newton shooting: {e}"));
            return Ok(());
        }
    };
    let moved = polished.unknowns - given;
    let u = units(&moved, &s.rounding);
    check.polished = Some(polished.unknowns.into());
    check.polish_iterations = polished.iterations;
    check.moved = Some(moved.into());
    check.rounding_units = Some(u);
    check.input = if at_given.end_residual.norm() < SATISFIED {
        InputVerdict::Satisfies
    } else if u <= 1.0 + 1e-6 {
        InputVerdict::Rounded
    } else {
        InputVerdict::Misses
    };
    if let Some(p) = options.fit {
        match fit(base, s, options, p, &polished) {
            Ok(f) => {
                // the printed parameter's own rounding
                let printed = s
                    .parameters
                    .iter()
                    .position(|(q, _)| *q == p)
                    .and_then(|k| s.parameter_rounding.get(k).copied())
                    .unwrap_or(0.0);
                if check.input == InputVerdict::Misses
                    && f.rounding_units <= 1.0 + 1e-6
                    && (f.value - f.given).abs() <= printed
                {
                    check.input = InputVerdict::RoundedParameter;
                }
                check.fit = Some(f);
            }
            Err(e) => check.fit_error = Some(describe(&e)),
        }
    }
    // the continuum curve's own topology and link
    let curve = continuum.solve(&polished.unknowns, CURVE_SAMPLES)?;
    let clamps = scene.clamps();
    let [down, up] = clamps.ray_directions();
    check.continuum_knot = closure_knot_along(&curve.centreline, [down, up])
        .ok()
        .and_then(|k| k.name);
    // the polygon's writhe converges as h²: two samplings give its value
    // and error
    let writhe = |points: &[nalgebra::Vector3<f64>]| {
        writhe_closed(&ray_closure(points, down, up, scene.measure().ray_length))
    };
    let fine = writhe(&curve.centreline);
    let half: Vec<_> = curve.centreline.iter().step_by(2).copied().collect();
    let coarse = writhe(&half);
    let writhe = fine + (fine - coarse) / 3.0;
    let tiny = |v: f64| 1e-10 * v.abs().max(1.0);
    let continuum_values = [
        (
            Quantity::Force,
            (curve.n0.as_slice().to_vec(), tiny(curve.n0.norm())),
        ),
        (
            Quantity::Moment,
            (curve.m0.as_slice().to_vec(), tiny(curve.m0.norm())),
        ),
        (Quantity::Twist, (vec![curve.twist], tiny(curve.twist))),
        (Quantity::Energy, (vec![curve.energy], tiny(curve.energy))),
        (
            Quantity::Link,
            (vec![curve.twist + writhe], (fine - coarse).abs() / 3.0),
        ),
    ];
    // the discrete rod from the polished shape at N, 2N, 4N
    let mut der_scene = scene.clone();
    set_unknowns(&mut der_scene, &polished.unknowns.into());
    let mut eqs: Vec<Equilibrium> = Vec::new();
    for n in options.segments {
        let e = equilibrium_near_start(&der_scene, Some(n))
            .with_context(|| format!("the discrete rod at N = {n}"))?;
        check.der.push(der_row(n, &e));
        eqs.push(e);
    }
    // the stretching penalty's model error, O(1/S): once more at N, S/10 (it hardly depends on N)
    let mut softer = der_scene.clone();
    softer.model.stretching_stiffness = Some(options.stretching_stiffness / 10.0);
    let soft = equilibrium_near_start(&softer, Some(options.segments[0]))
        .context("the discrete rod at N with a tenth of the stretching stiffness")?;
    let values = |q: Quantity, e: &Equilibrium| -> Option<Vec<f64>> {
        Some(match q {
            Quantity::Force => e.n0.to_vec(),
            Quantity::Moment => e.m0.to_vec(),
            Quantity::Twist => vec![e.twist],
            Quantity::Energy => vec![e.energy],
            Quantity::Link => vec![e.link],
            Quantity::LowestOmega2 => vec![*e.omega_squared.first()?],
        })
    };
    for q in [
        Quantity::Force,
        Quantity::Moment,
        Quantity::Twist,
        Quantity::Energy,
        Quantity::Link,
        Quantity::LowestOmega2,
    ] {
        let Some(v) = eqs.iter().map(|e| values(q, e)).collect::<Option<Vec<_>>>() else {
            continue;
        };
        let c = continuum_values
            .iter()
            .find(|(k, _)| *k == q)
            .map(|(_, v)| v.clone());
        let model = values(q, &soft).map_or(0.0, |w| distance(&w, &v[0]) / 9.0);
        check.estimates.push(estimate(
            q,
            [v[0].clone(), v[1].clone(), v[2].clone()],
            model,
            c,
        ));
    }
    check.claims = claims_checked(&s.claims, check);
    Ok(())
}

fn der_row(n: usize, e: &Equilibrium) -> DerRow {
    DerRow {
        segments: n,
        n0: e.n0,
        m0: e.m0,
        twist: e.twist,
        energy: e.energy,
        link: e.link,
        lowest_omega2: e.omega_squared.first().copied(),
        negative: e.negative_eigenvalues,
        walled: e.walled,
        knot: e.knot_name.clone(),
        iterations: e.iterations,
    }
}

fn distance(a: &[f64], b: &[f64]) -> f64 {
    a.iter()
        .zip(b)
        .map(|(x, y)| (x - y).powi(2))
        .sum::<f64>()
        .sqrt()
}

fn norm(a: &[f64]) -> f64 {
    a.iter().map(|x| x * x).sum::<f64>().sqrt()
}

/// Richardson extrapolation of three resolutions N, 2N, 4N of a second-order
/// method, with the error estimate from the two extrapolations' difference,
/// the model error `model` and the continuum's value with its own error.
fn estimate(
    quantity: Quantity,
    values: [Vec<f64>; 3],
    model: f64,
    continuum: Option<(Vec<f64>, f64)>,
) -> Estimate {
    let rich = |a: &[f64], b: &[f64]| -> Vec<f64> {
        a.iter().zip(b).map(|(x, y)| (4.0 * y - x) / 3.0).collect()
    };
    let (r1, r2) = (rich(&values[0], &values[1]), rich(&values[1], &values[2]));
    let order = (distance(&values[0], &values[1]) / distance(&values[1], &values[2])).log2();
    // the solves' own accuracy sets a floor
    let error = distance(&r1, &r2).max(1e-10 * norm(&r2));
    let difference = continuum.as_ref().map(|(c, _)| distance(c, &r2));
    let scale = norm(&r2).max(1e-300);
    let total = error + model + continuum.as_ref().map_or(0.0, |c| c.1);
    Estimate {
        quantity,
        values,
        order,
        error,
        model_error: model,
        continuum_error: continuum.as_ref().map(|c| c.1),
        difference,
        relative: difference.map(|d| d / scale),
        sigmas: difference.map(|d| d / total),
        agrees: difference.map(|d| d <= 3.0 * total || d <= 1e-9 * scale),
        extrapolated: r2,
        continuum: continuum.map(|c| c.0),
    }
}

fn claims_checked(claims: &Claims, check: &SolutionCheck) -> Vec<ClaimCheck> {
    let mut out = Vec::new();
    let finest = check.der.last();
    let number = |claim: &str, claimed: Printed, q: Quantity, out: &mut Vec<ClaimCheck>| {
        let Some(e) = check.estimate(q) else { return };
        let found = e.continuum.as_ref().unwrap_or(&e.extrapolated)[0];
        // a printed claim is good to one unit of its last digit (rounded or
        // truncated), beside the found value's own error
        let unit = 2.0 * claimed.half_unit;
        let off = (found - claimed.value).abs();
        out.push(ClaimCheck {
            claim: claim.into(),
            claimed: format!("{}", claimed.value),
            found: format!(
                "{found:.6} ± {:.1e} ({:.2} units of its last digit off)",
                e.error + e.continuum_error.unwrap_or(0.0),
                off / unit
            ),
            confirmed: off <= unit + 3.0 * (e.error + e.continuum_error.unwrap_or(0.0)),
        });
    };
    if let Some(v) = claims.twist {
        number("Tw", v, Quantity::Twist, &mut out);
    }
    if let Some(v) = claims.link {
        number("link", v, Quantity::Link, &mut out);
    }
    if let Some(v) = claims.energy {
        number("energy", v, Quantity::Energy, &mut out);
    }
    if let Some(v) = claims.lowest_omega2 {
        number("lowest ω²", v, Quantity::LowestOmega2, &mut out);
    }
    if let (Some(v), Some(d)) = (claims.stable, finest) {
        out.push(ClaimCheck {
            claim: "stable".into(),
            claimed: v.to_string(),
            found: format!(
                "{} ({} negative)",
                d.negative == 0 && check.der.iter().all(|r| r.negative == 0),
                d.negative
            ),
            confirmed: v == check.der.iter().all(|r| r.negative == 0),
        });
    }
    if let (Some(v), Some(d)) = (claims.walled, finest) {
        out.push(ClaimCheck {
            claim: "walled".into(),
            claimed: v.to_string(),
            found: d.walled.to_string(),
            confirmed: v == d.walled,
        });
    }
    if let Some(v) = &claims.knot {
        let found = finest.and_then(|d| d.knot.clone());
        out.push(ClaimCheck {
            claim: "knot".into(),
            claimed: v.clone(),
            found: found.clone().unwrap_or_else(|| "none".into()),
            confirmed: found.as_deref() == Some(v.as_str()),
        });
    }
    out
}

fn verdict_of(c: &SolutionCheck) -> Verdict {
    if let Some(e) = &c.error {
        return Verdict::Failed(e.clone());
    }
    match c.input {
        InputVerdict::NoSolutionNearby | InputVerdict::Misses => return Verdict::NotASolution,
        InputVerdict::Satisfies | InputVerdict::Rounded | InputVerdict::RoundedParameter => {}
    }
    if c.estimates.iter().any(|e| e.agrees == Some(false))
        || c.continuum_knot != c.der.last().and_then(|d| d.knot.clone())
    {
        return Verdict::MethodsDisagree;
    }
    if c.claims.iter().any(|k| !k.confirmed) {
        return Verdict::ClaimsRefuted;
    }
    Verdict::Confirmed
}

/// The parameter value whose polished solution lies closest to the given
/// unknowns (least squares in rounding units), by Gauss–Newton from the given
/// value, each solution continued from the last.
fn fit(
    base: &Scene,
    s: &Solution,
    options: &VerifyOptions,
    p: Parameter,
    start: &Polished,
) -> Result<Fit> {
    let given_value = s
        .parameters
        .iter()
        .find(|(q, _)| *q == p)
        .map(|(_, v)| *v)
        .unwrap_or_else(|| p.value(&base.clamps()));
    if !given_value.is_finite() {
        fail!("--fit {}: the scene does not set it", p.name());
    }
    let weights: Unknowns = Unknowns::from(s.rounding).map(|r| 1.0 / r.max(f64::MIN_POSITIVE));
    let given = Unknowns::from(s.unknowns);
    let solve_at = |v: f64, from: &Unknowns| -> Result<Unknowns> {
        let mut sol = s.clone();
        match sol.parameters.iter_mut().find(|(q, _)| *q == p) {
            Some(slot) => slot.1 = v,
            None => sol.parameters.push((p, v)),
        }
        let scene = scene_of(base, &sol, options)?;
        Ok(continuum_of(&scene, options)?.polish(from)?.unknowns)
    };
    let (mut v, mut u) = (given_value, start.unknowns);
    for _ in 0..12 {
        let h = 1e-6 * (1.0 + v.abs());
        let du = (solve_at(v + h, &u)? - solve_at(v - h, &u)?) / (2.0 * h);
        let (j, r) = (
            du.component_mul(&weights),
            (given - u).component_mul(&weights),
        );
        let jj = j.dot(&j);
        if !(jj > 0.0 && jj.is_finite()) {
            fail!("--fit {}: the solution does not move with it", p.name());
        }
        let dv = j.dot(&r) / jj;
        // steps of at most 1 % of the value's scale keep Newton on its branch
        let dv = dv.clamp(-0.01 * (1.0 + v.abs()), 0.01 * (1.0 + v.abs()));
        v += dv;
        u = solve_at(v, &u)?;
        if dv.abs() < 1e-13 * (1.0 + v.abs()) {
            break;
        }
    }
    Ok(Fit {
        parameter: p,
        given: given_value,
        value: v,
        unknowns: u.into(),
        rounding_units: units(&(u - given), &s.rounding),
    })
}

/// Verify all solutions (in parallel), reporting each as it is done (an
/// error from `on_done` stops the run once the solutions in progress are
/// done, and is returned); rows of the same parameters whose polished
/// unknowns differ are marked as different equilibria.
pub fn verify_all(
    base: &Scene,
    solutions: &[Solution],
    options: &VerifyOptions,
    on_done: &(dyn Fn(&SolutionCheck) -> Result<()> + Sync),
) -> Result<Vec<SolutionCheck>> {
    use rayon::prelude::*;
    if options.segments.iter().any(|&n| n < 4) {
        return Err(StudyError::Failed(
            "verify: --segments must be at least 4".into(),
        ));
    }
    let mut checks: Vec<SolutionCheck> = solutions
        .par_iter()
        .enumerate()
        .map(|(k, s)| {
            let c = verify_solution(base, k, s, options);
            on_done(&c)?;
            Ok(c)
        })
        .collect::<Result<_>>()?;
    for k in 0..checks.len() {
        for j in 0..k {
            let (a, b) = (&checks[j], &checks[k]);
            if a.given.parameters != b.given.parameters {
                continue;
            }
            let (Some(pa), Some(pb)) = (a.polished, b.polished) else {
                continue;
            };
            let (pa, pb) = (Unknowns::from(pa), Unknowns::from(pb));
            if (pa - pb).norm() > SAME_EQUILIBRIUM * pa.norm().max(pb.norm())
                && matches!(
                    checks[k].verdict,
                    Verdict::Confirmed | Verdict::ClaimsRefuted
                )
            {
                checks[k].verdict = Verdict::DifferentEquilibrium { of: j };
                break;
            }
        }
    }
    Ok(checks)
}

/// The shooting unknowns of a discrete equilibrium: its clamp reactions
/// (a strip's n(0), u1(0), m2(0), u3(0)) at its N, and those polished by
/// Newton shooting on the continuum equations.
#[derive(Clone, Debug, Serialize, Deserialize, PartialEq)]
pub struct ShootingUnknowns {
    /// From the discrete rod at its N (second-order accurate).
    pub discrete: [f64; 6],
    /// Polished: the continuum solution nearest them.
    pub polished: [f64; 6],
    /// The polished unknowns' s = 1 residual.
    pub residual: f64,
    /// Whether they are a strip's.
    pub strip: bool,
}

/// The shooting unknowns of the discrete equilibrium `state` of `model`
/// (the reverse of verify: the discrete rod finds the branch, shooting
/// polishes it).
pub fn shooting_unknowns(
    model: &crate::model::rod::RodModel,
    state: &crate::model::rod::RodState,
) -> Result<ShootingUnknowns> {
    let strip = matches!(model.law, Law::Strip { .. });
    let discrete = crate::study::polish::discrete_unknowns(model, state);
    let continuum = Continuum::of(model, state.clamps, VerifyOptions::default().tolerance)?;
    let polished = continuum
        .polish(&discrete)
        .context("polishing the discrete rod's unknowns by Newton shooting")?;
    Ok(ShootingUnknowns {
        discrete: discrete.into(),
        polished: polished.unknowns.into(),
        residual: polished.residual,
        strip,
    })
}
