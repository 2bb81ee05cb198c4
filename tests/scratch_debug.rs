use knotrod::equilibrium::Equilibrium;
use knotrod::model::energy::RodEnergy;
use knotrod::model::rod::{Law, RodModel};
use knotrod::stability::lowest_eigenvalues;

#[test]
fn debug_unstable_strip() {
    let text = std::fs::read_to_string("/tmp/try/strip_cont.json").unwrap();
    let v: serde_json::Value = serde_json::from_str(&text).unwrap();
    let eqs: Vec<Equilibrium> = serde_json::from_value(v["equilibria"].clone()).unwrap();
    let model = RodModel {
        segments: 100,
        k2: 3.0,
        k3: 3.0,
        stretching_stiffness: 640000.0,
        law: Law::Strip {
            regularisation: 0.05,
        },
    };
    let energy = RodEnergy::new(model);
    for e in eqs.iter().step_by(20) {
        let n = energy.map.len();
        let mut g = vec![0.0; n];
        let mut vals = vec![0.0; energy.pattern.nnz()];
        energy.hessian(&e.state, &mut g, &mut vals);
        let h = energy.pattern.to_dense(&vals);
        let mut ev: Vec<f64> = h.symmetric_eigen().eigenvalues.iter().copied().collect();
        ev.sort_by(|a, b| a.total_cmp(b));
        let mut ldlt = knotrod::solve::sparse::Ldlt::new(&energy.pattern);
        let sp = lowest_eigenvalues(&energy.pattern, &vals, None, 2, &mut ldlt).unwrap();
        println!(
            "φ {:.4} neg {} dense {:?} sparse {:?} gnorm {:.2e}",
            e.phi_over_2pi,
            e.negative_eigenvalues,
            &ev[..3],
            sp.values,
            g.iter().map(|x| x * x).sum::<f64>().sqrt()
        );
    }
}
