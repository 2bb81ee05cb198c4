use knotrod::model::energy::RodEnergy;
use knotrod::model::rod::{Clamps, RodModel, RodState};
use knotrod::solve::newton::{Newton, NewtonSettings};
use knotrod::stability::lowest_eigenvalues;
use nalgebra::Vector3;
fn lam(newton: &mut Newton, clamps: Clamps, n: usize) -> (f64, f64, usize) {
    let mut st = RodState::straight(n, clamps);
    newton
        .minimize(&mut st, &NewtonSettings::default())
        .unwrap();
    let m = newton.energy.map.len();
    let mut g = vec![0.0; m];
    let mut v = vec![0.0; newton.energy.pattern.nnz()];
    newton.energy.hessian(&st, &mut g, &mut v);
    let sp = lowest_eigenvalues(&newton.energy.pattern, &v, None, 3, &mut newton.ldlt).unwrap();
    let gr = newton.energy.full_gradient(&st);
    let nf = -(gr.nodes[0] + gr.nodes[1]);
    (sp.values[0], nf[2], sp.negative_count)
}
fn main() {
    let n = 200;
    let model = RodModel {
        segments: n,
        k2: 1.0,
        k3: 3.0,
        stretching_stiffness: 640000.0,
    };
    let mut newton = Newton::new(RodEnergy::new(model.clone()));
    for eps in [0.5, 0.9, 1.0, 1.1, 1.5] {
        let e = eps * 4.0 * std::f64::consts::PI.powi(2) / 640000.0;
        let (l, n3, neg) = lam(&mut newton, Clamps::new(1.0 - e, 0.0, 0.0), n);
        println!(
            "euler eps {eps}: lambda {l:e} n3 {n3} P/4pi2 {} neg {neg}",
            -n3 / (4.0 * std::f64::consts::PI.powi(2))
        );
    }
    for m in [8.5, 8.9, 8.98, 9.0, 9.5] {
        let phi = m / 3.0;
        let (l, n3, neg) = lam(
            &mut newton,
            Clamps {
                z_star: 1.0,
                delta: 0.0,
                phi,
            },
            n,
        );
        println!("twist M {m}: lambda {l:e} n3 {n3} neg {neg}");
    }
    let _ = Vector3::<f64>::zeros();
}
