//! The walls z = 0 and z = z* between which a walled configuration lies.

/// Clearance from the walls: the smallest distance of an interior local
/// minimum of z above z = 0 and of an interior local maximum below z = z*
/// (negative when outside). The clamped ends, which start on the walls, do not
/// count; `heights` are the interior node heights in order along the rod.
pub fn wall_clearance(heights: &[f64], z_star: f64) -> f64 {
    wall_clearance_between(heights, heights, z_star)
}

/// As [`wall_clearance`] for a body of some thickness in z: the interior
/// local minima of its lowest heights `low` against z = 0, the interior
/// local maxima of its highest heights `high` against z = z* (a ribbon
/// across its width: `geometry::ribbon::Ribbon::heights`).
pub fn wall_clearance_between(low: &[f64], high: &[f64], z_star: f64) -> f64 {
    let n = low.len().min(high.len());
    let mut clearance = f64::INFINITY;
    for i in 1..n.saturating_sub(1) {
        let (a, z, b) = (low[i - 1], low[i], low[i + 1]);
        if z <= a && z <= b {
            clearance = clearance.min(z);
        }
        let (a, z, b) = (high[i - 1], high[i], high[i + 1]);
        if z >= a && z >= b {
            clearance = clearance.min(z_star - z);
        }
    }
    clearance
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn clearance_sees_dips_and_bumps_but_not_the_ends() {
        // rises from the bottom wall, dips to 0.02, bumps to 0.09, ends at the top
        let z = [0.001, 0.05, 0.02, 0.06, 0.09, 0.07, 0.099];
        assert!((wall_clearance(&z, 0.1) - 0.01).abs() < 1e-15);
        let z = [0.001, 0.05, -0.02, 0.06, 0.099];
        assert!((wall_clearance(&z, 0.1) + 0.02).abs() < 1e-15);
    }
}
