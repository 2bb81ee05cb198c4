//! Scene validation: every value's range checked, the error naming the field.

use crate::model::rod::{Clamps, EndKind, Parameter};
use crate::scene::InitialShape;
use crate::scene::{
    MAX_NATURAL_STRAIN, MAX_POSITION, Scene, SceneError, finite, invalid, parameter_range,
    positive, short, unit_vector,
};

/// Most rows of a `model.natural_strains` table.
pub const MAX_NATURAL_ROWS: usize = 100_000;
/// Largest `[contact] margin`, in rod lengths.
pub const MAX_CONTACT_MARGIN: f64 = 0.25;

impl Scene {
    /// Check every value's range (sections in the order of the file).
    pub fn validate(&self) -> Result<(), SceneError> {
        self.check_model()?;
        self.check_clamps()?;
        // every value a study gives a parameter, in range before anything
        // is computed from it
        self.check_varied()?;
        self.check_initial()?;
        self.check_solver()?;
        self.check_continuation()?;
        self.check_loading()?;
        self.check_sweep()?;
        self.check_map()?;
        self.check_contact()?;
        self.check_diagnostics()?;
        self.check_stability()?;
        self.check_reference()?;
        self.check_budget_spec()?;
        self.check_load()?;
        self.check_ends()?;
        Ok(())
    }

    /// `[clamps] end` and `[clamps.start] kind`: a pinned or free end where
    /// the solver has an isolated equilibrium to find, and nothing asked of
    /// it that only a clamp can do.
    fn check_ends(&self) -> Result<(), SceneError> {
        use crate::scene::ModelKind;
        use EndKind::{Clamped, Free, Pinned};
        let ends = self.clamps().ends;
        if ends.both_clamped() {
            return Ok(());
        }
        if ends.start != Clamped && ends.end != Clamped {
            let why = match (ends.start, ends.end) {
                (Free, Free) if self.load.weight == 0.0 => {
                    "both ends free and no weight: rigid motions are unresisted, every placement \
                     is an equilibrium; clamp one end"
                }
                (Free, Free) => {
                    "both ends free: nothing holds the weight, there is no equilibrium; clamp one end"
                }
                (Pinned, Pinned) => {
                    "both ends pinned: the turn about the line through the two pins (and, for a \
                     straight rod, a uniform spin of the material frame) is unresisted, so the \
                     equilibria are not isolated; clamp one end"
                }
                _ => {
                    "a pinned end and a free one: the rod turns freely about the pin (about the \
                     weight's line through it under a weight), so the equilibria are not \
                     isolated; clamp one end"
                }
            };
            return Err(invalid("clamps.end", why));
        }
        if self.model.kind != ModelKind::Kirchhoff {
            return Err(invalid(
                "model.kind",
                format!(
                    "a {} end needs kind = \"kirchhoff\" for now: with u2 = 0 enforced, the \
                     natural condition m(1) = 0 at the end vertex asks also m2 = 0 of the \
                     constraint's multiplier, which makes the KKT system singular there",
                    if ends.start == Clamped {
                        ends.end.name()
                    } else {
                        ends.start.name()
                    }
                ),
            ));
        }
        if self.contact.is_some() {
            return Err(invalid(
                "contact",
                "contact needs both ends clamped for now (the rays continue the clamps, and a \
                 pinned end's ghost node is not in the contact rows)",
            ));
        }
        if ends.start != Clamped && self.initial.shape == InitialShape::Shooting {
            return Err(invalid(
                "initial.shape",
                "shooting integrates from the s = 0 clamp's frame: it needs a clamped s = 0 end",
            ));
        }
        // a parameter must move something the rod feels
        let check = |field: &'static str, p: Parameter| {
            if p.is_model() {
                // the model's scalars move no end
                return Ok(());
            }
            let kind = if p.moves_start() {
                ends.start
            } else {
                ends.end
            };
            let side = if p.moves_start() { "s = 0" } else { "s = 1" };
            match kind {
                Free => Err(invalid(
                    field,
                    format!(
                        "{} moves the {side} end, which is free: nothing holds it there",
                        p.name()
                    ),
                )),
                Pinned if p.only_turns() => Err(invalid(
                    field,
                    format!(
                        "{} only turns the {side} end, which is pinned: its frame is free, \
                         so the rod does not feel it",
                        p.name()
                    ),
                )),
                _ => Ok(()),
            }
        };
        if let Some(c) = &self.continuation {
            check("continuation.parameter", c.parameter)?;
        }
        if let Some(sw) = &self.sweep {
            check("sweep.parameter", sw.parameter)?;
        }
        if let Some(m) = &self.map {
            check("map.parameter", m.parameter)?;
            if let Some(sl) = &m.slices {
                check("map.slices.parameter", sl.parameter)?;
            }
        }
        for l in &self.loading {
            for (p, v) in [
                (Parameter::ZStar, l.z_star),
                (Parameter::Delta, l.delta),
                (Parameter::Phi, l.phi_over_2pi),
            ] {
                if v.is_some() {
                    check("loading", p)?;
                }
            }
            for p in l.targets.keys() {
                check("loading.targets", *p)?;
            }
        }
        Ok(())
    }

    /// `[reference]`: finite published values.
    fn check_reference(&self) -> Result<(), SceneError> {
        if let Some(r) = &self.reference {
            for v in r.n0.iter().flatten() {
                finite("reference.n0", *v)?;
            }
            for v in r.m0.iter().flatten() {
                finite("reference.m0", *v)?;
            }
            for (field, v) in [("reference.twist", r.twist), ("reference.link", r.link)] {
                if let Some(v) = v {
                    finite(field, v)?;
                }
            }
        }
        Ok(())
    }

    /// `[load]`: a finite weight of sensible size along a direction,
    /// wherever the weight is or can become non-zero (a study varying it).
    fn check_load(&self) -> Result<(), SceneError> {
        let l = &self.load;
        self.check_value("load.weight", Parameter::Weight, l.weight)?;
        for v in l.direction {
            finite("load.direction", v)?;
        }
        let varied = self.varied().contains(&Parameter::Weight);
        if l.weight != 0.0 || varied {
            unit_vector(l.direction).map_err(|why| {
                invalid(
                    "load.direction",
                    if varied && l.weight == 0.0 {
                        format!("{why} (the scene varies the weight, which then acts along it)")
                    } else {
                        why.to_string()
                    },
                )
            })?;
        }
        Ok(())
    }

    /// `v` as a value of the parameter `p`: finite and within its range
    /// (`parameter_range`, declared once in limits.rs), the error naming
    /// `field`, wherever the value comes from.
    fn check_value(&self, field: &'static str, p: Parameter, v: f64) -> Result<(), SceneError> {
        finite(field, v)?;
        let strain = self
            .model
            .natural_strains
            .values()
            .iter()
            .fold(0.0_f64, |m, u| m.max(u.abs()));
        let (lo, hi, unit) = parameter_range(p, strain);
        if (lo..=hi).contains(&v) {
            return Ok(());
        }
        Err(invalid(
            field,
            format!(
                "{} = {} is out of range: it must be in [{}, {}] ({unit})",
                p.name(),
                short(v),
                short(lo),
                short(hi)
            ),
        ))
    }

    /// `[model]`: a known kind, positive stiffnesses, N in range.
    fn check_model(&self) -> Result<(), SceneError> {
        let m = &self.model;
        positive("model.strip_regularisation", m.strip_regularisation)?;
        self.check_value("model.K2", Parameter::K2, m.k2)?;
        self.check_value("model.K3", Parameter::K3, m.k3)?;
        if m.segments < 4 || m.segments > 1_000_000 {
            return Err(invalid(
                "model.segments",
                format!("must be an integer in 4..=1000000, got {}", m.segments),
            ));
        }
        positive("model.rod_diameter", m.rod_diameter)?;
        if !(1e-5..=0.5).contains(&m.rod_diameter) {
            // the stretching stiffness 16/h² follows it; past 1e-5 it
            // swamps bending by more than f64 resolves
            return Err(invalid(
                "model.rod_diameter",
                format!(
                    "must be in [1e-5, 0.5] (rod lengths), got {}",
                    short(m.rod_diameter)
                ),
            ));
        }
        self.check_natural_strains()?;
        self.check_strip_width()?;
        if let Some(s) = m.stretching_stiffness {
            positive("model.stretching_stiffness", s)?;
            if s > 1e12 {
                return Err(invalid(
                    "model.stretching_stiffness",
                    format!("must be <= 1e12 (EA L²/EI), got {}", short(s)),
                ));
            }
        }
        Ok(())
    }

    /// `model.strip_width`: a ribbon narrow beside the rod's length, for the
    /// laws that have a flat section, measured where its measure is honoured.
    fn check_strip_width(&self) -> Result<(), SceneError> {
        let w = finite("model.strip_width", self.model.strip_width)?;
        if !(0.0..0.5).contains(&w) {
            // Sadowsky's energy is the limit of a strip narrow beside its
            // length; a ribbon half as wide as the rod is long is a plate
            return Err(invalid(
                "model.strip_width",
                format!(
                    "must be in [0, 0.5) (rod lengths): the strip law holds for a strip \
                     narrow beside its length, got {}",
                    short(w)
                ),
            ));
        }
        if w == 0.0 {
            return Ok(());
        }
        if self.model.kind == crate::scene::ModelKind::Kirchhoff {
            return Err(invalid(
                "model.strip_width",
                "a Kirchhoff rod has a circular section (model.rod_diameter); a width is \
                 for kind = \"strip\" or \"unbendable\"",
            ));
        }
        if self.contact.is_some() {
            return Err(invalid(
                "model.strip_width",
                "contact acts on a tube of diameter h round the centreline, not on the \
                 ribbon: use strip_width = 0 with [contact]",
            ));
        }
        if self.clamps.start.is_some() {
            return Err(invalid(
                "model.strip_width",
                "the ribbon's walls are heights along e3, the paper's s = 0 clamp: \
                 use strip_width = 0 with [clamps.start]",
            ));
        }
        Ok(())
    }

    /// `[clamps]`: finite, δ ≥ 0, the clamps no farther apart than the rod is long.
    fn check_clamps(&self) -> Result<(), SceneError> {
        use Parameter as P;
        let c = &self.clamps;
        let mut values = vec![
            ("clamps.z_star", P::ZStar, c.z_star),
            ("clamps.delta", P::Delta, c.delta),
            ("clamps.phi_over_2pi", P::Phi, c.phi_over_2pi),
            ("clamps.end_tilt", P::EndTilt, c.end_tilt),
            (
                "clamps.end_tilt_azimuth",
                P::EndTiltAzimuth,
                c.end_tilt_azimuth,
            ),
        ];
        if let Some([x, y]) = c.end_shift {
            values.extend([
                ("clamps.end_shift", P::EndX, x),
                ("clamps.end_shift", P::EndY, y),
            ]);
        }
        if let Some(st) = &c.start {
            let [x, y, z] = st.position;
            values.extend([
                ("clamps.start.position", P::StartX, x),
                ("clamps.start.position", P::StartY, y),
                ("clamps.start.position", P::StartZ, z),
                ("clamps.start.tilt", P::StartTilt, st.tilt),
                (
                    "clamps.start.tilt_azimuth",
                    P::StartTiltAzimuth,
                    st.tilt_azimuth,
                ),
                ("clamps.start.turn_over_2pi", P::StartTurn, st.turn_over_2pi),
            ]);
        }
        for (field, p, v) in values {
            self.check_value(field, p, v)?;
        }
        if let Some(r) = &c.end_rotation {
            r.quaternion()
                .map_err(|why| invalid("clamps.end_rotation", why))?;
        }
        if let Some(r) = c.start.as_ref().and_then(|st| st.rotation) {
            r.quaternion()
                .map_err(|why| invalid("clamps.start.rotation", why))?;
        }
        let general = !self.clamps().is_paper();
        if c.start.is_some()
            && self.model.kind == crate::scene::ModelKind::Strip
            && self.initial.shape == InitialShape::Shooting
        {
            return Err(invalid(
                "clamps.start",
                "strip shooting starts from the paper's s = 0 clamp (identity at the origin); \
                 start a strip with a general s = 0 clamp from another shape",
            ));
        }
        if general && self.initial.shape == InitialShape::DoubleRing {
            return Err(invalid(
                "initial.shape",
                "the double ring is unfolded to the paper's clamps only (no shift, tilt, rotation, [clamps.start] or pinned/free end)",
            ));
        }
        if general && self.initial.shape == InitialShape::Trefoil {
            return Err(invalid(
                "initial.shape",
                "the trefoil start is tied around the paper's clamps only (no shift, tilt, rotation, [clamps.start] or pinned/free end)",
            ));
        }
        reachable(["clamps.z_star", "clamps.delta"], &self.clamps())
    }

    /// The model's scalars a study varies: each meaningful for the law, and
    /// every value it is set to in range.
    fn check_varied(&self) -> Result<(), SceneError> {
        use crate::scene::ModelKind;
        for p in self.varied().into_iter().filter(Parameter::is_model) {
            let kind = self.model.kind;
            let why = match p {
                Parameter::K2 if kind != ModelKind::Kirchhoff => Some(
                    "K2 is a stiffness of the Kirchhoff law only (u2 = 0 for the strip and the unbendable rod)",
                ),
                Parameter::K3 if kind == ModelKind::Strip => {
                    Some("the strip law has no K3 (bending and twisting do not separate)")
                }
                Parameter::NaturalScale if kind == ModelKind::Strip => Some(
                    "the strip law is not affine in its natural curvature: vary it by a sweep of scenes instead",
                ),
                _ => None,
            };
            if let Some(why) = why {
                return Err(invalid(field_of(self, p), why));
            }
        }
        for (field, p, v) in self.study_values() {
            self.check_value(field, p, v)?;
        }
        Ok(())
    }

    /// Every value a study gives a parameter, with the field it comes from:
    /// a continuation's range, a sweep's values, a map's axes and slices, a
    /// loading path's targets (the scene's own fields are `check_clamps`').
    fn study_values(&self) -> Vec<(&'static str, Parameter, f64)> {
        let mut values: Vec<(&'static str, Parameter, f64)> = Vec::new();
        let branch = self.continuation.as_ref().map(|c| c.parameter);
        if let Some(c) = &self.continuation {
            values.extend(c.range.map(|v| ("continuation.range", c.parameter, v)));
        }
        if let Some(sw) = &self.sweep {
            values.extend(sw.values.iter().map(|v| ("sweep.values", sw.parameter, *v)));
        }
        if let Some(m) = &self.map {
            values.extend(m.range.map(|v| ("map.range", m.parameter, v)));
            // points of the map's plane: (map parameter, branch parameter)
            let slices = m
                .slices
                .iter()
                .flat_map(|sl| sl.trace_from.iter().flatten());
            let points = (m.trace_from.iter().map(|t| ("map.trace_from", t)))
                .chain(slices.map(|t| ("map.slices.trace_from", t)));
            for (field, [a, b]) in points {
                values.push((field, m.parameter, *a));
                values.extend(branch.map(|c| (field, c, *b)));
            }
        }
        if let Some(sl) = self.map.as_ref().and_then(|m| m.slices.as_ref()) {
            values.extend(
                sl.values
                    .iter()
                    .map(|v| ("map.slices.values", sl.parameter, *v)),
            );
            for v in sl.start_phi_over_2pi.iter().flatten() {
                values.push(("map.slices.start_phi_over_2pi", Parameter::Phi, *v));
            }
        }
        for l in &self.loading {
            for (field, p, v) in [
                ("loading.z_star", Parameter::ZStar, l.z_star),
                ("loading.delta", Parameter::Delta, l.delta),
                ("loading.phi_over_2pi", Parameter::Phi, l.phi_over_2pi),
            ] {
                values.extend(v.map(|v| (field, p, v)));
            }
            values.extend(l.targets.iter().map(|(p, v)| ("loading.targets", *p, *v)));
        }
        values
    }

    /// The clamps where `parameter` takes the value `v` and the other
    /// coordinates are the scene's own.
    fn clamps_at(&self, parameter: Parameter, v: f64) -> Clamps {
        parameter.with(&self.clamps(), v)
    }

    /// `model.natural_strains`: finite and of sensible size; a table sorted
    /// in s from 0 to 1 and not too long; only the components the law has.
    fn check_natural_strains(&self) -> Result<(), SceneError> {
        use crate::model::natural::NaturalStrains;
        use crate::scene::ModelKind;
        const FIELD: &str = "model.natural_strains";
        let m = &self.model;
        for v in m.natural_strains.values() {
            finite(FIELD, v)?;
            if v.abs() > MAX_NATURAL_STRAIN {
                return Err(invalid(
                    FIELD,
                    format!(
                        "each |û_i| must be <= {} (per rod length), got {}",
                        short(MAX_NATURAL_STRAIN),
                        short(v)
                    ),
                ));
            }
        }
        if let NaturalStrains::Table(rows) = &m.natural_strains {
            if !(2..=MAX_NATURAL_ROWS).contains(&rows.len()) {
                return Err(invalid(
                    FIELD,
                    format!(
                        "a table needs 2..={MAX_NATURAL_ROWS} rows [s, û1, û2, û3], got {}",
                        rows.len()
                    ),
                ));
            }
            for r in rows {
                finite(FIELD, r[0])?;
            }
            if let Some(w) = rows.windows(2).find(|w| w[1][0] <= w[0][0]) {
                return Err(invalid(
                    FIELD,
                    format!(
                        "the table's s must increase strictly, got {} then {}",
                        short(w[0][0]),
                        short(w[1][0])
                    ),
                ));
            }
            let (first, last) = (rows[0][0], rows[rows.len() - 1][0]);
            if first != 0.0 || last != 1.0 {
                return Err(invalid(
                    FIELD,
                    format!(
                        "the table must cover s in [0, 1] from its first row at s = 0 to its last at s = 1, got [{}, {}]",
                        short(first),
                        short(last)
                    ),
                ));
            }
        }
        let component = |k| !m.natural_strains.component_is_zero(k);
        if m.kind == ModelKind::Strip && (component(1) || component(2)) {
            return Err(invalid(
                FIELD,
                "û2 and û3 must be 0 for the strip law (u2 = 0 is enforced and the \
                 Sadowsky law has no natural twist): give only û1",
            ));
        }
        if m.kind == ModelKind::Unbendable && component(1) {
            return Err(invalid(
                FIELD,
                "û2 must be 0 for the unbendable law (u2 = 0 is enforced)",
            ));
        }
        Ok(())
    }

    /// `[initial]`: the data each shape needs.
    fn check_initial(&self) -> Result<(), SceneError> {
        let i = &self.initial;
        let strip = self.model.kind == crate::scene::ModelKind::Strip;
        let strip_fields = [
            ("initial.u1_0", i.u1_0),
            ("initial.m2_0", i.m2_0),
            ("initial.u3_0", i.u3_0),
        ];
        for (field, v) in strip_fields {
            if v.is_some() && !(strip && i.shape == InitialShape::Shooting) {
                return Err(invalid(
                    field,
                    "only for shape = \"shooting\" with kind = \"strip\"",
                ));
            }
        }
        if i.shape == InitialShape::Shooting {
            let n0 =
                i.n0.ok_or_else(|| invalid("initial.n0", "required for shape = \"shooting\""))?;
            for v in n0 {
                finite("initial.n0", v)?;
            }
            if strip {
                // the strip's unknowns at s = 0 are the paper's (Sec. 4):
                // n(0), u1(0), m2(0), u3(0); m1(0), m3(0) follow from the law
                if i.m0.is_some() {
                    return Err(invalid(
                        "initial.m0",
                        "not used for kind = \"strip\": give initial.u1_0, m2_0, u3_0",
                    ));
                }
                for (field, v) in strip_fields {
                    let v = v.ok_or_else(|| {
                        invalid(field, "required for shape = \"shooting\" of a strip")
                    })?;
                    finite(field, v)?;
                    if v.abs() > 1e4 {
                        return Err(invalid(
                            field,
                            format!("must be in [-1e4, 1e4], got {}", short(v)),
                        ));
                    }
                }
            } else {
                let m0 =
                    i.m0.ok_or_else(|| invalid("initial.m0", "required for shape = \"shooting\""))?;
                for v in m0 {
                    finite("initial.m0", v)?;
                }
            }
        }
        // sample intervals of a shooting start, or unfolding steps of the double ring
        // (each unfolding step is a Newton solve: far fewer of them)
        let (least, most) = if i.shape == InitialShape::DoubleRing {
            (1, 10_000)
        } else {
            (10, 1_000_000)
        };
        if let Some(s) = i.steps
            && !(least..=most).contains(&s)
        {
            return Err(invalid(
                "initial.steps",
                format!("must be in {least}..={most}, got {s}"),
            ));
        }
        for v in i.bump.iter().flatten() {
            finite("initial.bump", *v)?;
            if v.abs() > 10.0 {
                return Err(invalid(
                    "initial.bump",
                    format!(
                        "each component must be in [-10, 10] (rod lengths), got {}",
                        short(*v)
                    ),
                ));
            }
        }
        if i.shape == InitialShape::File && i.file.is_none() {
            return Err(invalid("initial.file", "required for shape = \"file\""));
        }
        Ok(())
    }

    /// `[solver]`: positive tolerances and a budget.
    fn check_solver(&self) -> Result<(), SceneError> {
        let s = &self.solver;
        positive("solver.gradient_tol", s.gradient_tol)?;
        positive("solver.max_step", s.max_step)?;
        if s.max_iterations == 0 {
            return Err(invalid("solver.max_iterations", "must be >= 1"));
        }
        Ok(())
    }

    /// `[continuation]`: a range holding the start, positive steps.
    fn check_continuation(&self) -> Result<(), SceneError> {
        if let Some(c) = &self.continuation {
            finite("continuation.range", c.range[0])?;
            finite("continuation.range", c.range[1])?;
            if c.range[0] >= c.range[1] {
                return Err(invalid(
                    "continuation.range",
                    "must be [lo, hi] with lo < hi",
                ));
            }
            let start = c.parameter.value(&self.clamps());
            if start < c.range[0] || start > c.range[1] {
                return Err(invalid(
                    "continuation.range",
                    format!("does not contain the start value {}", short(start)),
                ));
            }
            for (field, v) in [
                ("continuation.step", c.step),
                ("continuation.max_step", c.max_step),
            ] {
                if let Some(v) = v {
                    positive(field, v)?;
                }
            }
            if let Some(m) = c.max_points
                && m < 1
            {
                return Err(invalid("continuation.max_points", "must be >= 1"));
            }
            if c.polish && (self.contact.is_some() || !self.loading.is_empty()) {
                return Err(invalid(
                    "continuation.polish",
                    "the continuum equations have no contact and no loading path: \
                     polish a contact-free branch",
                ));
            }
        }
        Ok(())
    }

    /// `[[loading]]`: alone (no continuation), finite targets, step counts in range.
    fn check_loading(&self) -> Result<(), SceneError> {
        if !self.loading.is_empty() && self.continuation.is_some() {
            return Err(invalid(
                "loading",
                "a scene has either [[loading]] or [continuation], not both",
            ));
        }
        for l in &self.loading {
            if l.steps < 1 || l.steps > 1_000_000 {
                return Err(invalid(
                    "loading.steps",
                    format!("must be in 1..=1000000, got {}", l.steps),
                ));
            }
            if let Some(n) = l.step_iterations
                && !(1..=1_000_000_000).contains(&n)
            {
                return Err(invalid(
                    "loading.step_iterations",
                    format!("must be in 1..=1000000000, got {n}"),
                ));
            }
            for (field, v) in [
                ("loading.z_star", l.z_star),
                ("loading.delta", l.delta),
                ("loading.phi_over_2pi", l.phi_over_2pi),
            ] {
                if let Some(v) = v {
                    finite(field, v)?;
                }
            }
        }
        // each leg ends where the rod can reach
        let mut c = self.clamps();
        for l in &self.loading {
            c.z_star = l.z_star.unwrap_or(c.z_star);
            c.delta = l.delta.unwrap_or(c.delta);
            for (p, v) in &l.targets {
                finite("loading.targets", *v)?;
                c = p.with(&c, *v);
            }
            reachable(["loading.z_star", "loading.delta"], &c)?;
        }
        Ok(())
    }

    /// `[sweep]`: a continuation to repeat, finite values, another parameter.
    fn check_sweep(&self) -> Result<(), SceneError> {
        if let Some(sw) = &self.sweep {
            if self.continuation.is_none() {
                return Err(invalid("sweep", "needs a [continuation] to repeat"));
            }
            if sw.values.is_empty() {
                return Err(invalid("sweep.values", "must not be empty"));
            }
            for v in &sw.values {
                finite("sweep.values", *v)?;
                reachable(
                    ["sweep.values", "sweep.values"],
                    &self.clamps_at(sw.parameter, *v),
                )?;
            }
            if Some(sw.parameter) == self.continuation.as_ref().map(|c| c.parameter) {
                return Err(invalid(
                    "sweep.parameter",
                    "must differ from continuation.parameter",
                ));
            }
        }
        Ok(())
    }

    /// `[map]` and `[map.slices]`.
    fn check_map(&self) -> Result<(), SceneError> {
        if let Some(m) = &self.map {
            let Some(cont) = &self.continuation else {
                return Err(invalid("map", "needs a [continuation] giving the branches"));
            };
            if cont.parameter == m.parameter {
                return Err(invalid(
                    "map.parameter",
                    format!(
                        "must differ from continuation.parameter (both {}): the lines are \
                         branches in the one at values of the other",
                        m.parameter.name()
                    ),
                ));
            }
            finite("map.range", m.range[0])?;
            finite("map.range", m.range[1])?;
            if m.range[0] >= m.range[1] {
                return Err(invalid("map.range", "must be [lo, hi] with lo < hi"));
            }
            for v in m.range {
                reachable(["map.range", "map.range"], &self.clamps_at(m.parameter, v))?;
            }
            if m.lines == 0 || m.lines > 100_000 {
                return Err(invalid("map.lines", "must be in 1..=100000"));
            }
            if m.grid_columns < 2 || m.grid_columns > 100_000 {
                return Err(invalid("map.grid_columns", "must be in 2..=100000"));
            }
            positive("map.trace_step", m.trace_step)?;
            for v in m.trace_from.iter().flatten() {
                finite("map.trace_from", *v)?;
            }
            if let Some(sl) = &m.slices {
                if sl.values.is_empty() || sl.values.iter().any(|v| !v.is_finite()) {
                    return Err(invalid("map.slices.values", "must be finite and non-empty"));
                }
                if sl.values.windows(2).any(|w| w[1] <= w[0]) {
                    return Err(invalid("map.slices.values", "must be increasing"));
                }
                for v in &sl.values {
                    reachable(
                        ["map.slices.values", "map.slices.values"],
                        &self.clamps_at(sl.parameter, *v),
                    )?;
                }
                if sl.parameter == m.parameter
                    || Some(sl.parameter) == self.continuation.as_ref().map(|c| c.parameter)
                {
                    return Err(invalid(
                        "map.slices.parameter",
                        "must differ from map.parameter and continuation.parameter",
                    ));
                }
                if let Some(p) = &sl.start_phi_over_2pi
                    && p.len() != sl.values.len()
                {
                    return Err(invalid(
                        "map.slices.start_phi_over_2pi",
                        "needs one value per slice",
                    ));
                }
                for v in sl.trace_from.iter().flatten().flatten() {
                    finite("map.slices.trace_from", *v)?;
                }
                if let Some(p) = &sl.trace_from
                    && p.len() != sl.values.len()
                {
                    return Err(invalid(
                        "map.slices.trace_from",
                        "needs one point per slice",
                    ));
                }
            }
        }
        Ok(())
    }

    /// `[contact]`: a positive margin no larger than [`MAX_CONTACT_MARGIN`],
    /// finite obstacles.
    fn check_contact(&self) -> Result<(), SceneError> {
        if let Some(c) = &self.contact {
            positive("contact.margin", c.margin)?;
            if c.margin > MAX_CONTACT_MARGIN {
                return Err(invalid(
                    "contact.margin",
                    format!(
                        "must be at most {} rod lengths, got {}: pairs closer than h + margin \
                         become constraints, so past a quarter of the rod nearly every pair \
                         of the rod is one (the default is 0.02)",
                        short(MAX_CONTACT_MARGIN),
                        short(c.margin)
                    ),
                ));
            }
            for o in &c.obstacles {
                for v in o {
                    finite("contact.obstacles", *v)?;
                    // their directions are normalised differences
                    if v.abs() > MAX_POSITION {
                        return Err(invalid(
                            "contact.obstacles",
                            format!(
                                "each coordinate must be within ±{} rod lengths, got {}",
                                short(MAX_POSITION),
                                short(*v)
                            ),
                        ));
                    }
                }
            }
        }
        Ok(())
    }

    /// `[diagnostics]`: a gap below half the rod, a positive ray length, a
    /// tabled knot, and the paper's clearance where a map is traced.
    fn check_diagnostics(&self) -> Result<(), SceneError> {
        let d = &self.diagnostics;
        positive("diagnostics.self_distance_gap", d.self_distance_gap)?;
        if d.self_distance_gap >= 0.5 {
            return Err(invalid(
                "diagnostics.self_distance_gap",
                "must be < 0.5 (half the rod)",
            ));
        }
        positive("diagnostics.ray_length", d.ray_length)?;
        if d.ray_length > 1e12 {
            // the writhe's far-loop terms lose every digit past this
            return Err(invalid(
                "diagnostics.ray_length",
                format!("must be <= 1e12, got {}", short(d.ray_length)),
            ));
        }
        match crate::geometry::knot::alexander_of(&d.knot) {
            None => {
                return Err(SceneError::Invalid {
                    field: "diagnostics.knot",
                    reason: format!(
                        "\"{}\" is not a tabled knot: name a prime knot up to 10 crossings \
                         as \"3_1\" … \"10_165\", or a sum of them as \"3_1#4_1\"",
                        d.knot
                    ),
                });
            }
            Some(p) if p == [1] => {
                return Err(SceneError::Invalid {
                    field: "diagnostics.knot",
                    reason: "a good knot must be knotted: the unknot 0_1 is not one".into(),
                });
            }
            Some(_) => {}
        }
        if d.clearance == crate::analysis::class::Clearance::Diameter && self.map.is_some() {
            return Err(invalid(
                "diagnostics.clearance",
                "a map's boundary walk follows the paper's curves (walls, crossings, \
                 stability), not a self-distance of h: use clearance = \"centreline\" with [map]",
            ));
        }
        Ok(())
    }

    /// `[stability]`: a sensible eigenvalue count.
    fn check_stability(&self) -> Result<(), SceneError> {
        if self.stability.eigenvalues < 0 || self.stability.eigenvalues > 100 {
            return Err(invalid(
                "stability.eigenvalues",
                format!("must be in 0..=100, got {}", self.stability.eigenvalues),
            ));
        }
        Ok(())
    }
}

/// Clamps at (z*, δ) that a rod of length 1 can reach: finite, δ ≥ 0,
/// |z*| ≤ 1 and sqrt(z*² + δ²) ≤ 1; `fields` name z* and δ.
fn reachable(fields: [&'static str; 2], c: &Clamps) -> Result<(), SceneError> {
    let (z_star, delta) = (c.z_star, c.delta);
    let free = c.ends.start == EndKind::Free || c.ends.end == EndKind::Free;
    if !c.is_paper() {
        finite(fields[0], z_star)?;
        finite(fields[1], delta)?;
        if delta < 0.0 {
            return Err(invalid(
                fields[1],
                format!("δ must be >= 0, got {}", short(delta)),
            ));
        }
        // a free end has no point to reach
        let span = c.span();
        if !free && (!span.is_finite() || span > 1.0) {
            return Err(invalid(
                fields[0],
                format!(
                    "the clamps are farther apart than the rod's length: |r(1) − r(0)| = {} > 1",
                    short(span)
                ),
            ));
        }
        return Ok(());
    }
    finite(fields[0], z_star)?;
    finite(fields[1], delta)?;
    if delta < 0.0 {
        return Err(invalid(
            fields[1],
            format!("δ must be >= 0, got {}", short(delta)),
        ));
    }
    if z_star.abs() > 1.0 {
        return Err(invalid(
            fields[0],
            format!(
                "|z*| must be <= 1 (the rod has length 1), got {}",
                short(z_star)
            ),
        ));
    }
    if z_star.hypot(delta) > 1.0 {
        return Err(invalid(
            fields[1],
            format!(
                "the clamps are farther apart than the rod's length: sqrt(z*² + δ²) = {} > 1 (z* = {}, δ = {})",
                short(z_star.hypot(delta)),
                short(z_star),
                short(delta)
            ),
        ));
    }
    Ok(())
}

/// The scene field that names a varied parameter.
fn field_of(scene: &Scene, p: Parameter) -> &'static str {
    if scene
        .continuation
        .as_ref()
        .is_some_and(|c| c.parameter == p)
    {
        "continuation.parameter"
    } else if scene.sweep.as_ref().is_some_and(|s| s.parameter == p) {
        "sweep.parameter"
    } else if scene.map.as_ref().is_some_and(|m| m.parameter == p) {
        "map.parameter"
    } else if scene.map.is_some() {
        "map.slices.parameter"
    } else {
        "loading.targets"
    }
}
