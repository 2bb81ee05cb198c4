//! The fixed-step integrator of the reference shooting ODEs: classical RK4 on
//! a uniform grid of [0, 1] and cubic Hermite interpolation between its
//! samples (Newton on their s = 1 conditions is `solve::continuum::newton`).

use nalgebra::SVector;

/// Samples y(k / steps), k = 0..=steps, of y' = f(s, y) from y(0) = `y0` by
/// classical RK4.
pub fn rk4<const D: usize>(
    y0: SVector<f64, D>,
    steps: usize,
    f: impl Fn(f64, &SVector<f64, D>) -> SVector<f64, D>,
) -> Vec<SVector<f64, D>> {
    let mut y = y0;
    let ds = 1.0 / steps as f64;
    let mut samples = Vec::with_capacity(steps + 1);
    samples.push(y);
    for k in 0..steps {
        let s = k as f64 * ds;
        let a = f(s, &y);
        let b = f(s + 0.5 * ds, &(y + 0.5 * ds * a));
        let c = f(s + 0.5 * ds, &(y + 0.5 * ds * b));
        let d = f(s + ds, &(y + ds * c));
        y += ds / 6.0 * (a + 2.0 * b + 2.0 * c + d);
        samples.push(y);
    }
    samples
}

/// y(s) between the uniform `samples` of [0, 1] by cubic Hermite
/// interpolation with the exact derivative f(s, y) at both ends of its step
/// (fourth order, as RK4 itself).
pub fn hermite<const D: usize>(
    samples: &[SVector<f64, D>],
    s: f64,
    f: impl Fn(f64, &SVector<f64, D>) -> SVector<f64, D>,
) -> SVector<f64, D> {
    let steps = samples.len() - 1;
    let x = s.clamp(0.0, 1.0) * steps as f64;
    let k = (x.floor() as usize).min(steps - 1);
    let t = x - k as f64;
    let ds = 1.0 / steps as f64;
    let (y0, y1) = (&samples[k], &samples[k + 1]);
    let (f0, f1) = (f(k as f64 * ds, y0), f((k + 1) as f64 * ds, y1));
    let h00 = 2.0 * t * t * t - 3.0 * t * t + 1.0;
    let h10 = t * t * t - 2.0 * t * t + t;
    let h01 = -2.0 * t * t * t + 3.0 * t * t;
    let h11 = t * t * t - t * t;
    h00 * y0 + h10 * ds * f0 + h01 * y1 + h11 * ds * f1
}
