//! Near the doubly covered ring (paper Sec. 6, App. B): the one-contact curves
//! I and II that bound the wedge of knotted strips, computed numerically (the
//! strands passing through each other at c1, c2 are the knot changes of a
//! continuation) and by the paper's asymptotics.

use crate::analysis::event::{Event, EventKind};
use crate::scene::Scene;
use crate::solve::root::bisect_predicate;
use crate::study::error::{Context, Result, StudyError, fail};
use crate::study::observer::both;
use crate::study::run::run_scene;
use std::f64::consts::PI;

/// δ[1]/β of eq. (6.13): (1 − 1/cos(π/√2)) / 2π = 0.4219…
pub fn curve_i_first_order() -> f64 {
    (1.0 - 1.0 / (PI / 2f64.sqrt()).cos()) / (2.0 * PI)
}

/// δ[2]/β of eq. (6.14) = −0.5048…
pub fn curve_i_second_order() -> f64 {
    let r = 2f64.sqrt();
    let c = 1.0 + 1.0 / (PI / r).cos();
    -(r * PI * (2.0 / (r * PI).tan() + 1.0 / (PI / r).sin()) - 4.0 * c * c) / (4.0 * PI)
}

/// Curve I, eq. (6.15): δ_I ≈ 0.422 Δφ − 0.505 z* Δφ (exact coefficients).
pub fn curve_i(z_star: f64, delta_phi: f64) -> f64 {
    (curve_i_first_order() + curve_i_second_order() * z_star) * delta_phi
}

/// Curve II, eq. (6.18): δ_II ≈ (π/2) z*² Δφ.
pub fn curve_ii(z_star: f64, delta_phi: f64) -> f64 {
    0.5 * PI * z_star * z_star * delta_phi
}

/// A strip scene started from the double ring unfolded to (z*, δ, φ), with a
/// continuation section appended.
fn strip_scene(
    segments: usize,
    z: f64,
    delta: f64,
    phi_over_2pi: f64,
    cont: &str,
) -> Result<Scene> {
    Scene::parse(&format!(
        "[model]\nkind = \"strip\"\nsegments = {segments}\n\
         [clamps]\nz_star = {z}\ndelta = {delta}\nphi_over_2pi = {phi_over_2pi}\n\
         [initial]\nshape = \"double_ring\"\nsteps = 20\n\
         [stability]\neigenvalues = 1\n{cont}"
    ))
    .context("asymptotics scene")
}

fn crossings(scene: &Scene) -> Result<Vec<Event>> {
    let events = run_scene(scene, None, &mut ())?;
    Ok(events
        .into_iter()
        .filter(|e| e.kind == EventKind::Crossing)
        .collect())
}

/// The end shifts (δ_II, δ_I) where the strip at (z*, Δφ) passes through
/// itself: continuation in δ from inside the knotted wedge.
pub fn one_contact_shifts(segments: usize, z_star: f64, delta_phi: f64) -> Result<(f64, f64)> {
    let guess = curve_i(z_star, delta_phi);
    let step = guess / 40.0;
    let cont = format!(
        "[continuation]\nparameter = \"delta\"\nrange = [1e-9, {}]\ndirection = \"both\"\nstep = {step}\nmax_step = {step}\n",
        2.0 * guess
    );
    let scene = strip_scene(
        segments,
        z_star,
        0.5 * guess,
        1.0 - delta_phi / (2.0 * PI),
        &cont,
    )?;
    let mut at: Vec<f64> = crossings(&scene)?.iter().map(|e| e.delta).collect();
    at.sort_by(f64::total_cmp);
    match at.as_slice() {
        [lo, .., hi] => Ok((*lo, *hi)),
        _ => fail!("z* = {z_star}, Δφ = {delta_phi}: found crossings at δ = {at:?}, expected two"),
    }
}

/// Whether, at end shift δ and displacement z*, turning the clamp down from
/// φ = 2π crosses the one-contact curve (the strands pass at c1 and back at c2).
pub fn crosses_one_contact_curve(segments: usize, z_star: f64, delta: f64) -> Result<bool> {
    let cont = "[continuation]\nparameter = \"phi\"\nrange = [0.9, 0.99999]\ndirection = \"down\"\nstep = 0.0002\nmax_step = 0.0005\n";
    let start = 1.0 - 0.2 * delta / (2.0 * PI);
    let scene = strip_scene(segments, z_star, delta, start, cont)?;
    // the answer is known at the second crossing: the run stops there
    let mut seen = 0;
    let mut stop_at_second = both(
        |_| Ok(()),
        |e: &Event| {
            seen += usize::from(e.kind == EventKind::Crossing);
            if seen >= 2 {
                Err(StudyError::Observer("two crossings".into()))
            } else {
                Ok(())
            }
        },
    );
    match run_scene(&scene, None, &mut stop_at_second) {
        Err(StudyError::Observer(_)) => Ok(true),
        Err(e) => Err(e),
        Ok(events) => Ok(events
            .iter()
            .filter(|e| e.kind == EventKind::Crossing)
            .count()
            >= 2),
    }
}

/// Largest z* of the one-contact curve at end shift δ, by bisection on
/// whether a clamp rotation from φ = 2π crosses it (to `tol` in z*).
pub fn max_one_contact_z_star(segments: usize, delta: f64, tol: f64) -> Result<f64> {
    let (lo, hi) = (0.15, 0.30);
    if !crosses_one_contact_curve(segments, lo, delta)?
        || crosses_one_contact_curve(segments, hi, delta)?
    {
        fail!("δ = {delta}: the one-contact curve's maximum is not within z* ∈ [{lo}, {hi}]");
    }
    bisect_predicate(
        lo,
        hi,
        |lo, hi| hi - lo <= tol,
        |z_star| crosses_one_contact_curve(segments, z_star, delta),
    )
}
