//! Cost of the rod's per-step operations versus N (100 … 3200): energy,
//! gradient, Hessian assembly, one Newton step (factorisation + solve), the
//! lowest eigenvalue, the per-step diagnostics (writhe carried along the
//! branch), one continuation step with full diagnostics; and the Figure 3
//! branch end to end at N = 200.

use criterion::{BenchmarkId, Criterion, criterion_group, criterion_main};
use knotrod::analysis::equilibrium::{Conformation, Measure, analyse};
use knotrod::linalg::eigen::lowest_eigenvalues;
use knotrod::linalg::sparse::Ldlt;
use knotrod::model::energy::RodEnergy;
use knotrod::model::rod::Parameter;
use knotrod::scene::Scene;
use knotrod::solve::continuation::{ContinuationSettings, Tracer};
use knotrod::solve::minimizer::Minimizer;
use knotrod::study::start::solve_scene;
use std::path::Path;

const SIZES: [usize; 6] = [100, 200, 400, 800, 1600, 3200];

/// Builds the measured closure for one N from its equilibrium.
type Setup<'a> =
    &'a dyn Fn(usize, &knotrod::analysis::equilibrium::Equilibrium) -> Box<dyn FnMut()>;

fn bench(c: &mut Criterion) {
    let d = Scene::load(Path::new("scenes/appendix_d.toml")).unwrap();
    let measure = Measure {
        eigenvalues: 1,
        ..d.measure()
    };
    let solved: Vec<_> = SIZES
        .iter()
        .map(|&n| (n, solve_scene(&d, Some(n)).unwrap()))
        .collect();
    let mut group = |name: &str, f: Setup| {
        let mut g = c.benchmark_group(name);
        g.sample_size(10);
        for (n, eq) in &solved {
            let mut run = f(*n, eq);
            g.bench_with_input(BenchmarkId::from_parameter(n), n, |b, _| b.iter(&mut run));
        }
        g.finish();
    };
    group("energy", &|n, eq| {
        let energy = RodEnergy::new(d.rod_model(Some(n)));
        let state = eq.state.clone();
        Box::new(move || {
            energy.energy(&state);
        })
    });
    group("gradient", &|n, eq| {
        let energy = RodEnergy::new(d.rod_model(Some(n)));
        let state = eq.state.clone();
        let mut g = vec![0.0; energy.map.len()];
        Box::new(move || {
            energy.gradient(&state, &mut g);
        })
    });
    group("hessian", &|n, eq| {
        let energy = RodEnergy::new(d.rod_model(Some(n)));
        let state = eq.state.clone();
        let mut g = vec![0.0; energy.map.len()];
        let mut v = vec![0.0; energy.pattern.nnz()];
        Box::new(move || {
            energy.hessian(&state, &mut g, &mut v);
        })
    });
    group("newton_step", &|n, eq| {
        let energy = RodEnergy::new(d.rod_model(Some(n)));
        let state = eq.state.clone();
        let mut g = vec![0.0; energy.map.len()];
        let mut v = vec![0.0; energy.pattern.nnz()];
        energy.hessian(&state, &mut g, &mut v);
        let mut ldlt = Ldlt::new(&energy.pattern);
        Box::new(move || {
            ldlt.factor(&v).unwrap();
            let mut x = g.clone();
            ldlt.solve_in_place(&mut x);
        })
    });
    group("lowest_eigenvalue", &|n, eq| {
        let energy = RodEnergy::new(d.rod_model(Some(n)));
        let state = eq.state.clone();
        let mut g = vec![0.0; energy.map.len()];
        let mut v = vec![0.0; energy.pattern.nnz()];
        energy.hessian(&state, &mut g, &mut v);
        let mut ldlt = Ldlt::new(&energy.pattern);
        Box::new(move || {
            lowest_eigenvalues(&energy.pattern, &v, None, 1, &mut ldlt).unwrap();
        })
    });
    group("diagnostics_carried", &|_, eq| {
        let (state, previous) = (eq.state.clone(), eq.clone());
        let measure = measure.clone();
        Box::new(move || {
            Conformation::continued(&state, &measure, &previous);
        })
    });
    group("continuation_step", &|n, eq| {
        let energy = RodEnergy::new(d.rod_model(Some(n)));
        let mut newton = Minimizer::new(energy);
        let state = eq.state.clone();
        let previous = eq.clone();
        let measure = measure.clone();
        Box::new(move || {
            let mut tracer =
                Tracer::new(&mut newton, Parameter::Phi, ContinuationSettings::default());
            let a = tracer.start(state.clone(), 1.0).unwrap();
            let b = tracer.correct(&a, 0.005, None).unwrap();
            let report = knotrod::solve::outcome::SolveReport {
                converged: true,
                iterations: b.iterations,
                residual_history: vec![],
                gradient_norm: b.residual,
                energy: 0.0,
                factorizations: 0,
                contacts: Vec::new(),
                contact_rows: Vec::new(),
            };
            drop(tracer);
            knotrod::analysis::equilibrium::analyse_from(
                &mut newton,
                &b.state,
                &report,
                &measure,
                Some(&previous),
                Some(&b.hessian),
            )
            .unwrap();
        })
    });
    let _ = analyse;
    let mut fig3 = Scene::load(Path::new("scenes/fig3_kirchhoff.toml")).unwrap();
    if let Some(c) = fig3.continuation.as_mut() {
        c.switch_branches = false;
    }
    let mut g = c.benchmark_group("figure_3_branch");
    g.sample_size(10);
    g.bench_function("200", |b| {
        b.iter(|| knotrod::study::run::run_scene(&fig3, Some(200), &mut ()).unwrap())
    });
    g.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
