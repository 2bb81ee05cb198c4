use knotrod::model::energy::RodEnergy;
use knotrod::model::rod::{Clamps, RodModel, RodState};
use knotrod::model::shooting::{ShootingSolution, refine_shooting};
use knotrod::solve::newton::{Newton, NewtonSettings};
use nalgebra::Vector3;
fn main() {
    let n0 = Vector3::new(-24.743, 17.772, 37.145);
    let m0 = Vector3::new(7.5317, -8.7100, 4.529);
    let clamps = Clamps::new(0.115, 0.05, 0.802);
    let sol = ShootingSolution::integrate(n0, m0, 3.0, 3.0, 4000);
    println!(
        "shoot residual {:?} tw {}",
        sol.boundary_residual(&clamps).as_slice(),
        sol.twist()
    );
    let (rn, rm) = refine_shooting(n0, m0, 3.0, 3.0, &clamps, 4000).unwrap();
    println!("refined n0 {:?} m0 {:?}", rn.as_slice(), rm.as_slice());
    let sol = ShootingSolution::integrate(rn, rm, 3.0, 3.0, 4000);
    println!("refined tw {}", sol.twist());
    for n in [50, 100, 200, 400] {
        let model = RodModel {
            segments: n,
            k2: 3.0,
            k3: 3.0,
            stretching_stiffness: 640000.0,
        };
        let mut st = RodState::from_curve(n, clamps, |s| sol.position(s), |s| sol.d1(s));
        println!("N={n} initial tw {}", st.twist());
        let mut newton = Newton::new(RodEnergy::new(model.clone()));
        let t = std::time::Instant::now();
        let rep = newton.minimize(&mut st, &NewtonSettings::default());
        match rep {
            Ok(r) => println!(
                "  it {} res {:e} E {} tw {} time {:?} hist {:?}",
                r.iterations,
                r.gradient_norm,
                r.energy,
                st.twist(),
                t.elapsed(),
                r.residual_history
            ),
            Err(e) => println!("  err {e}"),
        }
        let g = newton.energy.full_gradient(&st);
        let nf = -(g.nodes[0] + g.nodes[1]);
        let mm = -(st.nodes[0].cross(&g.nodes[0])
            + st.nodes[1].cross(&g.nodes[1])
            + g.theta[0] * Vector3::z());
        println!("  n0 {:?} m0 {:?}", nf.as_slice(), mm.as_slice());
    }
}
