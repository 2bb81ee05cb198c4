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
use crate::analysis::event::PolishFailure;
use crate::geometry::closure::{closure_knot_along, ray_closure};
use crate::geometry::writhe::writhe_closed;
use crate::model::rod::{Law, Parameter};
use crate::scene::{InitialShape, Scene};
use crate::solve::continuum::{Continuum, Polished, Unknowns};
use crate::study::error::{Context, Result, StudyError, describe, fail};
use crate::study::polish::FOLD_RESOLUTION;
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
    /// Claimed to lie at a fold (limit point) of its branch: at every N the
    /// discrete rod is then solved at its own fold, which lies O(h²) from
    /// the continuum's (at the given value it may have no equilibrium).
    #[serde(default)]
    pub fold: Option<FoldClaim>,
}

/// A claim that a solution lies at a fold of its branch.
#[derive(Clone, Copy, Debug, Serialize, Deserialize, PartialEq)]
pub struct FoldClaim {
    /// The branch's parameter, in which the branch turns back there.
    pub parameter: Parameter,
    /// How far the claimant's location of the fold may be off in it (AUTO's
    /// own location tolerance; 0 where none is stated).
    pub tolerance: f64,
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
    /// The lowest ω² computed, ascending.
    pub omega_squared: Vec<f64>,
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
    /// The parameter's value at a fold.
    Fold,
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
            Quantity::Fold => "fold's parameter",
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
    /// The continuum's value (for ω², its shooting determinant's, where
    /// both ends are clamped).
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

/// How a claim fared.
#[derive(Clone, Copy, Debug, Serialize, Deserialize, PartialEq, Eq)]
pub enum ClaimOutcome {
    /// What was found, within its error bar.
    Confirmed,
    /// Not what was found, beyond its error bar.
    Refuted,
    /// The error bar does not decide it (it straddles the claim's boundary,
    /// or the discrete rod did not converge).
    Undecided,
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
    /// Confirmed, refuted or undecided.
    pub outcome: ClaimOutcome,
}

impl ClaimCheck {
    /// Confirmed.
    pub fn confirmed(&self) -> bool {
        self.outcome == ClaimOutcome::Confirmed
    }

    /// Refuted.
    pub fn refuted(&self) -> bool {
        self.outcome == ClaimOutcome::Refuted
    }
}

/// Error bars are this many times the summed error estimates wide (for
/// agreement, signs of eigenvalues and claims alike).
pub const BAR: f64 = 3.0;

/// Observed orders accepted as the second-order method's asymptotic range:
/// below 1 the resolutions do not converge; above 2 the error estimate is
/// conservative, and up to 4 is common for eigenvalues at the default N
/// (Appendix E's lowest ω² converges at 3.5 from N = 100).
pub const ORDERS: std::ops::RangeInclusive<f64> = 1.0..=4.0;

/// One eigenvalue ω²_k of the second variation at N, 2N, 4N, extrapolated.
#[derive(Clone, Debug, Serialize, Deserialize, PartialEq)]
pub struct Omega2 {
    /// At N, 2N, 4N.
    pub values: [f64; 3],
    /// Richardson value (2N, 4N).
    pub extrapolated: f64,
    /// Discretisation error |R(N, 2N) − R(2N, 4N)|.
    pub error: f64,
    /// Stretching stiffness error |ω²(S) − ω²(S/10)| / 9 at N.
    pub model_error: f64,
    /// Observed order.
    pub order: f64,
}

/// The sign of an extrapolated eigenvalue, given its bar.
#[derive(Clone, Copy, Debug, Serialize, Deserialize, PartialEq, Eq)]
pub enum Sign {
    /// Above zero by more than its bar.
    Positive,
    /// Below zero by more than its bar.
    Negative,
    /// Its bar straddles zero.
    Undecided,
}

impl Omega2 {
    /// Half-width of its bar: [`BAR`] times the summed errors.
    pub fn bar(&self) -> f64 {
        BAR * (self.error + self.model_error)
    }

    /// Its sign, given its bar.
    pub fn sign(&self) -> Sign {
        if self.extrapolated - self.bar() > 0.0 {
            Sign::Positive
        } else if self.extrapolated + self.bar() < 0.0 {
            Sign::Negative
        } else {
            Sign::Undecided
        }
    }
}

/// Stability of the extrapolated equilibrium: from the Richardson values of
/// its lowest eigenvalues and their bars (not from the discrete rod's
/// inertia at any one N, which near a change of stability is on the wrong
/// side of it at coarse N).
#[derive(Clone, Debug, Serialize, Deserialize, PartialEq)]
pub struct Stability {
    /// The lowest eigenvalues, ascending at 4N.
    pub eigenvalues: Vec<Omega2>,
    /// Eigenvalues below zero by more than their bar.
    pub negative: usize,
    /// Eigenvalues whose bar straddles zero.
    pub undecided: usize,
    /// An eigenvalue above zero by more than its bar was computed: the
    /// count is complete.
    pub complete: bool,
}

impl Stability {
    /// Stable (Some(true)), unstable (Some(false)) or undecided (None).
    pub fn stable(&self) -> Option<bool> {
        if self.negative > 0 {
            Some(false)
        } else if self.undecided > 0 || !self.complete {
            None
        } else {
            Some(true)
        }
    }

    /// The negative count, when it is decided.
    pub fn negative(&self) -> Option<usize> {
        (self.undecided == 0 && self.complete).then_some(self.negative)
    }
}

/// Why the discrete rod and the continuum do not confirm each other.
#[derive(Clone, Debug, Serialize, Deserialize, PartialEq)]
pub enum Disagreement {
    /// The continuum's value lies outside the extrapolation's bar.
    Differs(Quantity),
    /// The continuum curve's knot type is not the discrete rod's.
    Knot {
        /// The continuum curve's.
        continuum: Option<String>,
        /// The discrete rod's at 4N.
        discrete: Option<String>,
    },
    /// The continuum's count of negative directions (conjugate points) is
    /// not the discrete rod's extrapolated one.
    Inertia {
        /// The continuum's.
        continuum: usize,
        /// The discrete rod's.
        discrete: usize,
    },
    /// The discrete rod's knot type changes with N: the three resolutions
    /// are not one equilibrium.
    KnotChangesWithN(Vec<Option<String>>),
    /// The negative count changes with N and an eigenvalue that crosses zero
    /// does not converge (observed order outside [`ORDERS`], or not
    /// computed): the three resolutions are not one equilibrium.
    InertiaChangesWithN(Vec<usize>),
    /// A quantity's observed order lies outside [`ORDERS`]: N, 2N, 4N are not
    /// in the method's asymptotic range and the extrapolation's error
    /// estimate means nothing.
    Order {
        /// Which.
        quantity: Quantity,
        /// Its observed order.
        order: f64,
    },
}

/// The setting a solution was verified in (the report's header).
#[derive(Clone, Debug, Serialize, Deserialize, PartialEq)]
pub struct Setting {
    /// z*, δ, φ/2π and every other clamp parameter of the resolved scene.
    pub clamps: Vec<(Parameter, f64)>,
    /// K2 = B22/B11.
    pub k2: f64,
    /// K3 = B33/B11.
    pub k3: f64,
    /// The strip law's regularisation ε (None for a rod).
    pub strip_epsilon: Option<f64>,
    /// Weight w L³/B11 (vector).
    pub weight: [f64; 3],
    /// Stretching stiffness S of the discrete rod.
    pub stiffness: f64,
    /// The adaptive integrator's tolerance.
    pub tolerance: f64,
    /// N, 2N, 4N.
    pub segments: [usize; 3],
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
        /// Some of its claims are refuted (the verdict line names them).
        claims_refuted: bool,
    },
    /// The discrete rod does not converge to the continuum solution, or not
    /// to one equilibrium as N grows.
    MethodsDisagree {
        /// Why.
        why: Vec<Disagreement>,
    },
    /// The claims are not what was found.
    ClaimsRefuted,
    /// Confirmed by both methods, with the claims.
    Confirmed,
}

/// A claimed fold, checked: the discrete rod's own folds at N, 2N, 4N and
/// the continuum's, located from the finest.
#[derive(Clone, Debug, Serialize, Deserialize, PartialEq)]
pub struct FoldCheck {
    /// The branch's parameter.
    pub parameter: Parameter,
    /// The given value (where the fold is claimed).
    pub given: f64,
    /// The claimant's location tolerance.
    pub tolerance: f64,
    /// The discrete rod's fold at N, 2N, 4N.
    pub discrete: [f64; 3],
    /// The eigenvalue that vanishes there (the fold's null direction, left
    /// out of the stability: its sign is the location's round-off).
    pub null_omega2: [f64; 3],
    /// The continuum's fold (the root of its shooting Jacobian's bordered
    /// determinant, from the discrete fold at 4N) and its error.
    pub continuum: Option<(f64, f64)>,
    /// Why the continuum's fold could not be located.
    pub continuum_failure: Option<PolishFailure>,
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
    /// Why no solution was found near the input (the integration from it or
    /// its Newton polish failed).
    pub input_error: Option<String>,
    /// The setting: the resolved scene's parameters, N and S.
    pub setting: Option<Setting>,
    /// The fitted parameter, if asked.
    pub fit: Option<Fit>,
    /// Why the fit failed, if it did.
    pub fit_error: Option<String>,
    /// Knot of the continuum curve's ray closure.
    pub continuum_knot: Option<String>,
    /// Eigenvalues ω² < 0 of the continuum's (A.4), counted by conjugate
    /// points (None where the continuum's stability is not covered).
    #[serde(default)]
    pub continuum_negative: Option<usize>,
    /// At a claimed fold: the discrete rod's folds and the continuum's.
    #[serde(default)]
    pub fold: Option<FoldCheck>,
    /// The discrete rod at N, 2N, 4N.
    pub der: Vec<DerRow>,
    /// The extrapolated quantities against the continuum.
    pub estimates: Vec<Estimate>,
    /// Stability from the extrapolated eigenvalues.
    pub stability: Option<Stability>,
    /// Why the two methods do not confirm each other (empty if they do).
    pub disagreements: Vec<Disagreement>,
    /// The first earlier row at the same parameters that polishes to the
    /// same equilibrium.
    pub same_as: Option<usize>,
    /// The claims checked.
    pub claims: Vec<ClaimCheck>,
    /// The verdict.
    pub verdict: Verdict,
    /// Why a step failed.
    pub error: Option<String>,
}

impl SolutionCheck {
    /// Nothing found yet about solution `s`, row `index`.
    fn blank(index: usize, s: &Solution) -> SolutionCheck {
        SolutionCheck {
            index,
            given: s.clone(),
            law: String::new(),
            end_residual: None,
            polished: None,
            polish_iterations: 0,
            moved: None,
            rounding_units: None,
            input: InputVerdict::NoSolutionNearby,
            input_error: None,
            setting: None,
            fit: None,
            fit_error: None,
            continuum_knot: None,
            continuum_negative: None,
            fold: None,
            der: vec![],
            estimates: vec![],
            stability: None,
            disagreements: vec![],
            same_as: None,
            claims: vec![],
            verdict: Verdict::Failed(String::new()),
            error: None,
        }
    }

    /// The estimate of a quantity.
    pub fn estimate(&self, q: Quantity) -> Option<&Estimate> {
        self.estimates.iter().find(|e| e.quantity == q)
    }

    /// Negative directions of the extrapolated equilibrium, when decided.
    pub fn negative(&self) -> Option<usize> {
        self.stability.as_ref().and_then(Stability::negative)
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
    scene.stability.eigenvalues = scene.stability.eigenvalues.max(EIGENVALUES as i64);
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
/// Eigenvalues computed at first (more when they are all negative).
const EIGENVALUES: usize = 4;
/// The most eigenvalues computed.
const MAX_EIGENVALUES: usize = 100;
/// A quantity that changes by less than this (relative) from N to 2N is
/// converged already at N: its observed order is not checked (it is then
/// set by round-off and the stiffness error, e.g. an ω² of −1771.7 that
/// moves by 1e-5 relative at order 0.6).
const RESOLVED: f64 = 1e-4;

/// Verify one solution against `base`.
pub fn verify_solution(
    base: &Scene,
    index: usize,
    s: &Solution,
    options: &VerifyOptions,
) -> SolutionCheck {
    let mut check = SolutionCheck::blank(index, s);
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
    check.setting = Some(setting_of(&scene, options));
    let continuum = continuum_of(&scene, options)?;
    let given = Unknowns::from(s.unknowns);
    // input that cannot be integrated or polished is no solution (a verdict
    // on the input, not a failure of the check)
    let at_given = match continuum.solve(&given, 0) {
        Ok(a) => a,
        Err(e) => {
            check.input = InputVerdict::NoSolutionNearby;
            check.input_error = Some(format!("integrating from the given unknowns: {e}"));
            return Ok(());
        }
    };
    check.end_residual = Some(at_given.end_residual.into());
    let polished = match continuum.polish(&given) {
        Ok(p) => p,
        Err(e) => {
            check.input = InputVerdict::NoSolutionNearby;
            check.input_error = Some(format!("polishing by Newton shooting: {e}"));
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
    if matches!(
        check.input,
        InputVerdict::Misses | InputVerdict::NoSolutionNearby
    ) {
        // the polished solution is another one: its rod and claims are not
        // this row's
        return Ok(());
    }
    let claimed_knot = s.claims.knot.as_deref().map(knot_claim).transpose()?;
    let found = match s.fold {
        None => at_parameters(&scene, &continuum, &polished.unknowns, options)?,
        Some(claim) => at_fold(&scene, &polished.unknowns, claim, options)?,
    };
    check.continuum_knot = found.continuum_knot;
    check.continuum_negative = found.continuum_negative;
    let (eqs, soft) = (&found.eqs, &found.soft);
    check.der = options
        .segments
        .iter()
        .zip(eqs)
        .map(|(&n, e)| der_row(n, e))
        .collect();
    check.stability = found.stability;
    let values = |q: Quantity, e: &Equilibrium| -> Option<Vec<f64>> {
        Some(match q {
            Quantity::Force => e.n0.to_vec(),
            Quantity::Moment => e.m0.to_vec(),
            Quantity::Twist => vec![e.twist],
            Quantity::Energy => vec![e.energy],
            Quantity::Link => vec![e.link],
            Quantity::LowestOmega2 => vec![*e.omega_squared.first()?],
            Quantity::Fold => return None,
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
        let c = found
            .continuum
            .iter()
            .find(|(k, _)| *k == q)
            .map(|(_, v)| v.clone());
        let model = values(q, soft).map_or(0.0, |w| distance(&w, &v[0]) / 9.0);
        check.estimates.push(estimate(
            q,
            [v[0].clone(), v[1].clone(), v[2].clone()],
            model,
            c,
        ));
    }
    if let Some((fold, soft_value)) = found.fold {
        check.estimates.push(estimate(
            Quantity::Fold,
            fold.discrete.map(|v| vec![v]),
            (soft_value - fold.discrete[0]).abs() / 9.0,
            fold.continuum.map(|(v, e)| (vec![v], e)),
        ));
        check.fold = Some(fold);
    }
    check.disagreements = disagreements(check);
    check.claims = claims_checked(&s.claims, claimed_knot.as_deref(), check);
    Ok(())
}

/// A quantity of the continuum solution: its value and error.
type ContinuumValue = (Quantity, (Vec<f64>, f64));

/// What the two methods found of one row, before they are compared.
struct Found {
    /// The discrete rod at N, 2N, 4N.
    eqs: Vec<Equilibrium>,
    /// At N with a tenth of the stretching stiffness.
    soft: Equilibrium,
    /// Stability from the extrapolated eigenvalues.
    stability: Option<Stability>,
    /// The continuum's quantities, each with its error.
    continuum: Vec<ContinuumValue>,
    /// The continuum curve's knot type.
    continuum_knot: Option<String>,
    /// The continuum's negative directions (conjugate points).
    continuum_negative: Option<usize>,
    /// At a fold: the folds, and the softer rod's fold value.
    fold: Option<(FoldCheck, f64)>,
}

/// The continuum solution `p` at the scene's parameters: its knot type and
/// its quantities, each with its error (`relative` of its size, the link
/// with its writhe's sampling error).
fn continuum_values(
    scene: &Scene,
    continuum: &Continuum,
    p: &Unknowns,
    relative: f64,
) -> Result<(Option<String>, Vec<ContinuumValue>)> {
    let curve = continuum.solve(p, CURVE_SAMPLES)?;
    let clamps = scene.clamps();
    let [down, up] = clamps.ray_directions();
    let knot = closure_knot_along(&curve.centreline, [down, up])
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
    let tiny = |v: f64| relative * v.abs().max(1.0);
    let values = vec![
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
    Ok((knot, values))
}

/// The discrete rod from the polished shape `p` at the given parameters,
/// and the continuum solution there.
fn at_parameters(
    scene: &Scene,
    continuum: &Continuum,
    p: &Unknowns,
    options: &VerifyOptions,
) -> Result<Found> {
    let (continuum_knot, mut values) = continuum_values(scene, continuum, p, 1e-10)?;
    let mut der_scene = scene.clone();
    set_unknowns(&mut der_scene, &(*p).into());
    // as many eigenvalues as it takes to see a positive one
    let (eqs, soft, stability) = loop {
        let (eqs, soft) = discrete_rods(&der_scene, options)?;
        let stability = stability_of(&eqs, &soft);
        if enough_eigenvalues(&stability, &der_scene) {
            break (eqs, soft, stability);
        }
        more_eigenvalues(&mut der_scene);
    };
    // stability on the continuum, by the shooting determinant of (A.4) and
    // its conjugate points: the second method for ω² and the inertia (only
    // where both ends are clamped; elsewhere the discrete rod's alone)
    let mut continuum_negative = None;
    if let Some(lowest) = eqs.last().and_then(|e| e.omega_squared.first())
        && let Ok(spectrum) = continuum.lowest_frequencies(p, 1, lowest.abs())
    {
        values.push((
            Quantity::LowestOmega2,
            (spectrum.values.clone(), spectrum.errors[0]),
        ));
        continuum_negative = Some(spectrum.negative);
    }
    Ok(Found {
        eqs,
        soft,
        stability,
        continuum: values,
        continuum_knot,
        continuum_negative,
        fold: None,
    })
}

fn enough_eigenvalues(stability: &Option<Stability>, scene: &Scene) -> bool {
    stability.as_ref().is_none_or(|s| s.complete)
        || scene.stability.eigenvalues as usize >= MAX_EIGENVALUES
}

fn more_eigenvalues(scene: &mut Scene) {
    let computed = scene.stability.eigenvalues as usize;
    scene.stability.eigenvalues = (2 * computed).min(MAX_EIGENVALUES) as i64;
}

/// The discrete rod at its own fold at N, 2N, 4N (and at N with a tenth of
/// the stiffness), from the polished shape `p`; the continuum's fold located
/// from the finest; the continuum solution and spectrum there.
fn at_fold(
    scene: &Scene,
    p: &Unknowns,
    claim: FoldClaim,
    options: &VerifyOptions,
) -> Result<Found> {
    let parameter = claim.parameter;
    let mut der_scene = scene.clone();
    set_unknowns(&mut der_scene, &(*p).into());
    let (folds, soft, stability) = loop {
        let (folds, soft) = discrete_folds(&der_scene, options, parameter)?;
        let eqs: Vec<Equilibrium> = folds.iter().map(|f| f.equilibrium.clone()).collect();
        let stability = stability_of(&eqs, &soft.equilibrium);
        if enough_eigenvalues(&stability, &der_scene) {
            break (folds, soft, stability);
        }
        more_eigenvalues(&mut der_scene);
    };
    let finest = &folds[2];
    let n4 = options.segments[2];
    let model = der_scene.rod_model(Some(n4));
    let mut event = [crate::analysis::event::Event::at(
        crate::analysis::event::EventKind::Fold,
        &finest.state.clamps,
        finest.state.twist(),
        0,
        String::new(),
    )];
    crate::study::polish::polish_events(
        &model,
        parameter,
        &scene.measure(),
        &mut event,
        std::slice::from_ref(&finest.state),
    );
    let [event] = event;
    let mut fold = FoldCheck {
        parameter,
        given: parameter.value(&scene.clamps()),
        tolerance: claim.tolerance,
        discrete: [folds[0].value, folds[1].value, folds[2].value],
        null_omega2: [
            folds[0].null_omega2,
            folds[1].null_omega2,
            folds[2].null_omega2,
        ],
        continuum: None,
        continuum_failure: None,
    };
    let (mut continuum_knot, mut values, mut continuum_negative) = (None, vec![], None);
    match event.continuum {
        Some(c) => {
            fold.continuum = Some((c.value, c.error));
            let mut at = scene.clone();
            at.set(parameter, c.value);
            let continuum = continuum_of(&at, options)?;
            let u = Unknowns::from(c.unknowns);
            (continuum_knot, values) = continuum_values(&at, &continuum, &u, FOLD_RESOLUTION)?;
            // the continuum's spectrum there, its null direction left out as
            // the discrete rod's is
            let lowest = finest.equilibrium.omega_squared.first().copied();
            if let Some(lowest) = lowest
                && let Ok(spectrum) = continuum.lowest_frequencies(&u, 2, lowest.abs())
            {
                let null = if spectrum.values[0].abs() <= spectrum.values[1].abs() {
                    0
                } else {
                    1
                };
                let other = 1 - null;
                values.push((
                    Quantity::LowestOmega2,
                    (vec![spectrum.values[other]], spectrum.errors[other]),
                ));
                let below = usize::from(spectrum.values[null] < 0.0);
                continuum_negative = spectrum.negative.checked_sub(below);
            }
        }
        // (the polish says why on the event; its detail is the discrete
        // rod's text)
        None => fold.continuum_failure = event.not_polished.clone(),
    }
    let eqs = folds.into_iter().map(|f| f.equilibrium).collect();
    Ok(Found {
        eqs,
        soft: soft.equilibrium,
        stability,
        continuum: values,
        continuum_knot,
        continuum_negative,
        fold: Some((fold, soft.value)),
    })
}

/// A discrete fold with its vanishing eigenvalue taken out of its spectrum.
struct Folded {
    value: f64,
    state: crate::model::rod::RodState,
    equilibrium: Equilibrium,
    null_omega2: f64,
}

fn folded(f: crate::study::fold::DiscreteFold) -> Folded {
    let mut equilibrium = f.equilibrium;
    let omega = &mut equilibrium.omega_squared;
    let null = (0..omega.len())
        .min_by(|&a, &b| omega[a].abs().total_cmp(&omega[b].abs()))
        .map_or(f64::NAN, |k| omega.remove(k));
    // the inertia counts the null direction on the side its round-off puts
    // it (its Lanczos value and the LDLᵀ pivots may differ there): the
    // count beside it is that of the other negative eigenvalues, when the
    // computed ones reach a positive one
    let below = omega.iter().filter(|w| **w < 0.0).count();
    let complete = omega.iter().any(|w| *w > 0.0);
    let inertia = &mut equilibrium.negative_eigenvalues;
    if complete && *inertia > below {
        *inertia = below.max(inertia.saturating_sub(1));
    } else if !complete && null < 0.0 {
        *inertia = inertia.saturating_sub(1);
    }
    Folded {
        value: f.value,
        state: f.state,
        equilibrium,
        null_omega2: null,
    }
}

/// The discrete rod at its own fold in `parameter` at N, 2N, 4N, and at N
/// with a tenth of the stretching stiffness.
fn discrete_folds(
    scene: &Scene,
    options: &VerifyOptions,
    parameter: Parameter,
) -> Result<(Vec<Folded>, Folded)> {
    let mut folds = Vec::new();
    for n in options.segments {
        let f = crate::study::fold::fold_near(scene, Some(n), parameter)
            .with_context(|| format!("the discrete rod's fold at N = {n}"))?;
        folds.push(folded(f));
    }
    let mut softer = scene.clone();
    softer.model.stretching_stiffness = Some(options.stretching_stiffness / 10.0);
    let soft = crate::study::fold::fold_near(&softer, Some(options.segments[0]), parameter)
        .context("the discrete rod's fold at N with a tenth of the stretching stiffness")?;
    Ok((folds, folded(soft)))
}

/// The discrete rod at N, 2N, 4N, and at N with a tenth of the stretching
/// stiffness (its model error is O(1/S) and hardly depends on N).
fn discrete_rods(
    scene: &Scene,
    options: &VerifyOptions,
) -> Result<(Vec<Equilibrium>, Equilibrium)> {
    let mut eqs = Vec::new();
    for n in options.segments {
        eqs.push(
            equilibrium_near_start(scene, Some(n))
                .with_context(|| format!("the discrete rod at N = {n}"))?,
        );
    }
    let mut softer = scene.clone();
    softer.model.stretching_stiffness = Some(options.stretching_stiffness / 10.0);
    let soft = equilibrium_near_start(&softer, Some(options.segments[0]))
        .context("the discrete rod at N with a tenth of the stretching stiffness")?;
    Ok((eqs, soft))
}

/// The resolved scene's parameters, as the report's header states them.
fn setting_of(scene: &Scene, options: &VerifyOptions) -> Setting {
    let model = scene.rod_model(None);
    let clamps = scene.clamps();
    Setting {
        clamps: Parameter::ALL
            .iter()
            .map(|&p| (p, p.value(&clamps)))
            .collect(),
        k2: model.k2,
        k3: model.k3,
        strip_epsilon: match model.law {
            Law::Strip { regularisation } => Some(regularisation),
            _ => None,
        },
        weight: model.weight,
        stiffness: options.stretching_stiffness,
        tolerance: options.tolerance,
        segments: options.segments,
    }
}

/// The extrapolated lowest eigenvalues (as many as every resolution and the
/// softer rod computed), their signs and count.
fn stability_of(eqs: &[Equilibrium], soft: &Equilibrium) -> Option<Stability> {
    let k = eqs
        .iter()
        .chain([soft])
        .map(|e| e.omega_squared.len())
        .min()?;
    if k == 0 {
        return None;
    }
    let eigenvalues: Vec<Omega2> = (0..k)
        .map(|i| {
            let values = [
                eqs[0].omega_squared[i],
                eqs[1].omega_squared[i],
                eqs[2].omega_squared[i],
            ];
            let (extrapolated, error, order) = richardson(&values.map(|v| vec![v]));
            Omega2 {
                values,
                extrapolated: extrapolated[0],
                error,
                model_error: (soft.omega_squared[i] - values[0]).abs() / 9.0,
                order,
            }
        })
        .collect();
    let count = |sign: Sign| eigenvalues.iter().filter(|e| e.sign() == sign).count();
    Some(Stability {
        negative: count(Sign::Negative),
        undecided: count(Sign::Undecided),
        complete: count(Sign::Positive) > 0,
        eigenvalues,
    })
}

/// Whether an observed order is checked: the quantity still changes from
/// N to 2N by more than [`RESOLVED`].
fn order_checked(values: &[Vec<f64>; 3]) -> bool {
    distance(&values[0], &values[1]) > RESOLVED * norm(&values[2]).max(1.0)
}

/// Why the methods do not confirm each other: the continuum outside a
/// bar, another knot type; or the discrete rod not one converging
/// equilibrium (its knot type or, through an eigenvalue that does not
/// converge, its inertia changes with N; an observed order outside
/// [`ORDERS`]).
fn disagreements(c: &SolutionCheck) -> Vec<Disagreement> {
    let mut out = Vec::new();
    let knots: Vec<Option<String>> = c.der.iter().map(|d| d.knot.clone()).collect();
    if knots.windows(2).any(|w| w[0] != w[1]) {
        out.push(Disagreement::KnotChangesWithN(knots));
    }
    let negative: Vec<usize> = c.der.iter().map(|d| d.negative).collect();
    if negative.windows(2).any(|w| w[0] != w[1]) {
        // the eigenvalues that cross zero must converge through it
        let crossing = negative.iter().copied().max().unwrap_or(0);
        let eigen = c.stability.as_ref().map_or(&[][..], |s| &s.eigenvalues[..]);
        let converges = |e: &Omega2| ORDERS.contains(&e.order);
        if eigen.len() < crossing || !eigen[..crossing].iter().all(converges) {
            out.push(Disagreement::InertiaChangesWithN(negative));
        }
    }
    for e in &c.estimates {
        if order_checked(&e.values) && !ORDERS.contains(&e.order) {
            out.push(Disagreement::Order {
                quantity: e.quantity,
                order: e.order,
            });
        }
    }
    for e in &c.estimates {
        if e.agrees == Some(false) {
            out.push(Disagreement::Differs(e.quantity));
        }
    }
    let decided = c.stability.as_ref().and_then(Stability::negative);
    if let (Some(continuum), Some(discrete)) = (c.continuum_negative, decided)
        && continuum != discrete
    {
        out.push(Disagreement::Inertia {
            continuum,
            discrete,
        });
    }
    let discrete = c.der.last().and_then(|d| d.knot.clone());
    if c.continuum_knot != discrete {
        out.push(Disagreement::Knot {
            continuum: c.continuum_knot.clone(),
            discrete,
        });
    }
    out
}

/// Common names of knots, beside the table's own ("3_1", "4_1", …).
const KNOT_ALIASES: [(&str, &str); 6] = [
    ("unknot", "0_1"),
    ("trefoil", "3_1"),
    ("figure-eight", "4_1"),
    ("figure eight", "4_1"),
    ("figure-8", "4_1"),
    ("cinquefoil", "5_1"),
];

/// A claimed knot type in the table's name ("trefoil" is "3_1"), or an
/// error naming the field and the accepted forms.
pub fn knot_claim(name: &str) -> Result<String> {
    let trimmed = name.trim();
    let canonical = KNOT_ALIASES
        .iter()
        .find(|(alias, _)| alias.eq_ignore_ascii_case(trimmed))
        .map_or(trimmed, |(_, n)| *n);
    if crate::geometry::knot::alexander_of(canonical).is_none() {
        let aliases: Vec<&str> = KNOT_ALIASES.iter().map(|(a, _)| *a).collect();
        fail!(
            "claim knot = {name:?}: not a knot name; give a tabled knot (\"0_1\", \"3_1\", \"4_1\", … \
             to 10 crossings), a sum of them (\"3_1#4_1\") or one of {}",
            aliases.join(", ")
        );
    }
    Ok(canonical.to_string())
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
        omega_squared: e.omega_squared.clone(),
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
/// method: the value R(2N, 4N), its error estimate |R(N, 2N) − R(2N, 4N)|
/// and the observed order.
fn richardson(values: &[Vec<f64>; 3]) -> (Vec<f64>, f64, f64) {
    let rich = |a: &[f64], b: &[f64]| -> Vec<f64> {
        a.iter().zip(b).map(|(x, y)| (4.0 * y - x) / 3.0).collect()
    };
    let (r1, r2) = (rich(&values[0], &values[1]), rich(&values[1], &values[2]));
    let order = (distance(&values[0], &values[1]) / distance(&values[1], &values[2])).log2();
    // the solves' own accuracy sets a floor
    let error = distance(&r1, &r2).max(1e-10 * norm(&r2));
    (r2, error, order)
}

/// A quantity's Richardson extrapolation with the model error `model`,
/// against the continuum's value with its own error.
fn estimate(
    quantity: Quantity,
    values: [Vec<f64>; 3],
    model: f64,
    continuum: Option<(Vec<f64>, f64)>,
) -> Estimate {
    let (r2, error, order) = richardson(&values);
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

fn claims_checked(
    claims: &Claims,
    claimed_knot: Option<&str>,
    check: &SolutionCheck,
) -> Vec<ClaimCheck> {
    let mut out = Vec::new();
    let finest = check.der.last();
    // what rests on the discrete rod alone is undecided when it did not
    // converge to one equilibrium
    let converged = !check.disagreements.iter().any(|d| {
        matches!(
            d,
            Disagreement::KnotChangesWithN(_)
                | Disagreement::InertiaChangesWithN(_)
                | Disagreement::Order { .. }
        )
    });
    let decided = |confirmed: bool| match (converged, confirmed) {
        (false, _) => ClaimOutcome::Undecided,
        (true, true) => ClaimOutcome::Confirmed,
        (true, false) => ClaimOutcome::Refuted,
    };
    let number = |claim: &str, claimed: Printed, q: Quantity, out: &mut Vec<ClaimCheck>| {
        let Some(e) = check.estimate(q) else { return };
        let found = e.continuum.as_ref().unwrap_or(&e.extrapolated)[0];
        // a printed claim is good to one unit of its last digit (rounded or
        // truncated), beside every error stated for the found value
        let unit = 2.0 * claimed.half_unit;
        let off = (found - claimed.value).abs();
        let errors = e.error + e.model_error + e.continuum_error.unwrap_or(0.0);
        let confirmed = off <= unit + BAR * errors;
        out.push(ClaimCheck {
            claim: claim.into(),
            claimed: format!("{}", claimed.value),
            found: format!(
                "{found:.6} ± {errors:.1e} ({:.2} units of its last digit off)",
                off / unit
            ),
            outcome: decided(confirmed),
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
    if let Some(v) = claims.stable {
        let stability = check.stability.as_ref();
        let (outcome, found) = match stability.and_then(Stability::stable) {
            Some(found) => (decided(found == v), found.to_string()),
            None => (ClaimOutcome::Undecided, "undecided".to_string()),
        };
        let lowest = stability
            .and_then(|s| s.eigenvalues.first())
            .map_or("no eigenvalue computed".into(), |e| {
                format!("lowest ω² {:.6} ± {:.1e}", e.extrapolated, e.bar())
            });
        let negative = stability.map_or(String::new(), |s| match s.negative() {
            Some(k) => format!("{k} negative; "),
            None => format!("{} negative, {} undecided; ", s.negative, s.undecided),
        });
        out.push(ClaimCheck {
            claim: "stable".into(),
            claimed: v.to_string(),
            found: format!("{found} ({negative}{lowest})"),
            outcome,
        });
    }
    if let (Some(v), Some(d)) = (claims.walled, finest) {
        out.push(ClaimCheck {
            claim: "walled".into(),
            claimed: v.to_string(),
            found: d.walled.to_string(),
            outcome: decided(v == d.walled),
        });
    }
    if let (Some(fold), Some(e)) = (&check.fold, check.estimate(Quantity::Fold)) {
        // where the continuum's fold could not be located, the discrete
        // rod's extrapolated one stands for it
        let found = e.continuum.as_ref().unwrap_or(&e.extrapolated)[0];
        let rounding = check
            .given
            .parameters
            .iter()
            .position(|(q, _)| *q == fold.parameter)
            .and_then(|k| check.given.parameter_rounding.get(k).copied())
            .unwrap_or(0.0);
        let errors = e.error + e.model_error + e.continuum_error.unwrap_or(0.0);
        let off = (found - fold.given).abs();
        out.push(ClaimCheck {
            claim: format!("fold in {}", fold.parameter.name()),
            claimed: format!("{} ± {:.1e}", fold.given, fold.tolerance),
            found: format!("{found:.12} ± {errors:.1e} ({off:.1e} off)"),
            outcome: decided(off <= 2.0 * rounding + fold.tolerance + BAR * errors),
        });
    }
    if let (Some(given), Some(v)) = (&claims.knot, claimed_knot) {
        let found = finest.and_then(|d| d.knot.clone());
        // the table names every knot of a polynomial, joined by " or "
        let confirmed = found
            .as_deref()
            .is_some_and(|f| f.split(" or ").any(|n| n == v));
        out.push(ClaimCheck {
            claim: "knot".into(),
            claimed: if given == v {
                v.to_string()
            } else {
                format!("{given} ({v})")
            },
            found: found.unwrap_or_else(|| "none".into()),
            outcome: decided(confirmed),
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
    if !c.disagreements.is_empty() {
        return Verdict::MethodsDisagree {
            why: c.disagreements.clone(),
        };
    }
    if c.claims.iter().any(ClaimCheck::refuted) {
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
/// done, and is returned); rows at the same parameters are grouped by the
/// equilibrium they polish to, and the rows of every group after the first
/// marked as different equilibria from the first.
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
    // the workers count into the run's work
    let work = crate::linalg::counters::current();
    let mut checks: Vec<SolutionCheck> = solutions
        .par_iter()
        .enumerate()
        .map(|(k, s)| {
            let c = crate::linalg::counters::within(work.as_ref(), || {
                verify_solution(base, k, s, options)
            });
            on_done(&c)?;
            Ok(c)
        })
        .collect::<Result<_>>()?;
    mark_equilibria(base, solutions, options, &mut checks);
    Ok(checks)
}

/// The resolved scene a row is solved in, without its unknowns: rows with
/// equal keys are at the same parameters, however they were given.
fn parameters_key(base: &Scene, s: &Solution, options: &VerifyOptions) -> Option<String> {
    let mut scene = scene_of(base, s, options).ok()?;
    set_unknowns(&mut scene, &[0.0; 6]);
    serde_json::to_string(&scene).ok()
}

/// Rows at the same parameters, grouped by the equilibrium they polish to
/// (in row order): each row's first twin is `same_as`; the rows of the
/// second and later groups are a different equilibrium from the first
/// group's first row.
fn mark_equilibria(
    base: &Scene,
    solutions: &[Solution],
    options: &VerifyOptions,
    checks: &mut [SolutionCheck],
) {
    let keys: Vec<Option<String>> = solutions
        .iter()
        .map(|s| parameters_key(base, s, options))
        .collect();
    // only solutions take part: a row that is none polishes to someone else's
    let solution = |c: &SolutionCheck| {
        matches!(
            c.input,
            InputVerdict::Satisfies | InputVerdict::Rounded | InputVerdict::RoundedParameter
        ) && c.polished.is_some()
    };
    let same = |a: [f64; 6], b: [f64; 6]| {
        let (a, b) = (Unknowns::from(a), Unknowns::from(b));
        (a - b).norm() <= SAME_EQUILIBRIUM * a.norm().max(b.norm())
    };
    // per parameter key: the groups' first rows, in row order
    let mut groups: Vec<(&String, Vec<usize>)> = Vec::new();
    for k in 0..checks.len() {
        let (Some(key), true) = (&keys[k], solution(&checks[k])) else {
            continue;
        };
        let polished = checks[k].polished.unwrap_or_default();
        let slot = match groups.iter().position(|(g, _)| *g == key) {
            Some(i) => i,
            None => {
                groups.push((key, vec![]));
                groups.len() - 1
            }
        };
        let firsts = &mut groups[slot].1;
        let group = match firsts
            .iter()
            .position(|&f| same(checks[f].polished.unwrap_or_default(), polished))
        {
            Some(g) => {
                checks[k].same_as = Some(firsts[g]);
                g
            }
            None => {
                firsts.push(k);
                firsts.len() - 1
            }
        };
        let c = &mut checks[k];
        if group > 0 && matches!(c.verdict, Verdict::Confirmed | Verdict::ClaimsRefuted) {
            c.verdict = Verdict::DifferentEquilibrium {
                of: firsts[0],
                claims_refuted: c.claims.iter().any(ClaimCheck::refuted),
            };
        }
    }
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

#[cfg(test)]
mod tests {
    use super::*;

    fn lowest_omega2(values: [f64; 3], model_error: f64) -> Estimate {
        estimate(
            Quantity::LowestOmega2,
            values.map(|v| vec![v]),
            model_error,
            None,
        )
    }

    #[test]
    fn a_claimed_omega2_is_judged_against_every_stated_error() {
        // the Appendix D knot at N = 200, 400, 800: Richardson 167.740942
        // ± 9.5e-4, the stiffness error 3.2e-3; the true value is 167.7379
        let mut check = SolutionCheck::blank(0, &solution());
        let e = lowest_omega2([167.725924, 167.7379, 167.7401815], 3.2e-3);
        assert!((e.error - 9.5e-4).abs() < 1e-5, "{e:?}");
        assert!((e.extrapolated[0] - 167.740942).abs() < 1e-6, "{e:?}");
        check.estimates.push(e);
        let claim = |value: f64| Claims {
            lowest_omega2: Some(Printed {
                value,
                half_unit: 5e-5,
            }),
            ..Claims::default()
        };
        let k = &claims_checked(&claim(167.7379), None, &check)[0];
        assert_eq!(k.outcome, ClaimOutcome::Confirmed, "{k:?}");
        // beyond those errors it is refuted
        let k = &claims_checked(&claim(167.72), None, &check)[0];
        assert_eq!(k.outcome, ClaimOutcome::Refuted, "{k:?}");
    }

    #[test]
    fn an_order_far_from_two_is_a_disagreement_and_roundoff_is_not() {
        // the strip at N = 400, 800, 1600: n(0) jumps at 1600
        let mut check = SolutionCheck::blank(0, &solution());
        check.estimates.push(estimate(
            Quantity::Force,
            [
                vec![-8.43, 1.608, 72.08],
                vec![-8.44, 1.61, 72.1],
                vec![-3.91, 2.10, 55.2],
            ],
            0.0,
            Some((vec![-8.43069, 1.60824, 72.0790], 1e-9)),
        ));
        // the link, exact to the solves' accuracy: no order
        check.estimates.push(estimate(
            Quantity::Link,
            [vec![3.76], vec![3.76 + 3e-10], vec![3.76 + 2e-10]],
            0.0,
            Some((vec![3.76], 1e-6)),
        ));
        let why = disagreements(&check);
        assert_eq!(why.len(), 1, "{why:?}");
        assert!(
            matches!(why[0], Disagreement::Order { quantity: Quantity::Force, order } if order < -8.0),
            "{why:?}"
        );
    }

    #[test]
    fn knot_claims_take_common_names_and_refuse_unknown_ones() {
        assert_eq!(knot_claim("trefoil").unwrap(), "3_1");
        assert_eq!(knot_claim("Figure-Eight").unwrap(), "4_1");
        assert_eq!(knot_claim("3_1#4_1").unwrap(), "3_1#4_1");
        let e = describe(&knot_claim("granny knot").unwrap_err());
        assert!(
            e.contains("claim knot") && e.contains("3_1") && e.contains("unknot"),
            "{e}"
        );
    }

    fn solution() -> Solution {
        Solution {
            name: "row".into(),
            parameters: vec![],
            parameter_rounding: vec![],
            unknowns: [0.0; 6],
            rounding: [1e-9; 6],
            claims: Claims::default(),
            fold: None,
        }
    }
}
