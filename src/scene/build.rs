//! Turning a validated scene into its parts: interface terms, their tables, the air bearing.

use std::sync::Arc;

use serde::Serialize;

use super::{ContactSpec, IntermolecularSpec, LubricantSpec, Scene, WettingSpec};
use crate::cache::codec::{malformed, Reader, Writer};
use crate::cache::{CacheReport, TableCache};
use crate::force::{
    lj_zero, AirBearing, Electrostatic, Footprint, GapReference, GreenwoodWilliamson,
    InterfaceForces, InterfaceTerm, Intermolecular, Meniscus, MeniscusParams, Pickup,
    ReynoldsBearing, Wetting,
};
use crate::quadrature::{Table, TableOptions};
use crate::surface::{Discrete, GaussianHeights, PeakDistribution, PeakModel};
use crate::{Error, Result};

/// Every table of a scene: its interface forces and its lubricant menisci.
pub(crate) type SceneTables = (InterfaceForces, Option<Meniscus>);

/// The payload of a table-cache entry for `tables`.
pub(crate) fn encode_tables((forces, meniscus): &SceneTables) -> Vec<u8> {
    let mut w = Writer::new();
    forces.encode_tables(&mut w);
    let table = meniscus.as_ref().and_then(Meniscus::table);
    w.bool(table.is_some());
    if let Some(t) = table {
        t.encode(&mut w);
    }
    w.into_bytes()
}

/// Prefixes the field of an input error with `prefix`.
fn in_field(e: Error, prefix: &str) -> Error {
    match e {
        Error::InvalidInput { field, reason } => Error::InvalidInput {
            field: format!("{prefix}{field}"),
            reason,
        },
        other => other,
    }
}

impl Scene {
    /// The asperity peak-height distribution (errors name `surface.peaks.<field>`).
    pub fn peaks(&self) -> Result<Arc<dyn PeakDistribution>> {
        self.surface.peaks.build().map_err(|e| match e {
            Error::InvalidInput { field, reason } if field.starts_with("peaks") => {
                Error::InvalidInput {
                    field: format!("surface.{field}"),
                    reason,
                }
            }
            other => in_field(other, "surface.peaks."),
        })
    }

    /// Heights of a discrete peak ensemble (given or sampled), `None` for continuous laws.
    fn discrete_peak_heights(&self) -> Result<Option<Vec<f64>>> {
        Ok(match &self.surface.peaks {
            PeakModel::Discrete { heights_m } => Some(heights_m.clone()),
            PeakModel::DiscreteSampled { from, n, seed } => {
                let parent = from
                    .build()
                    .map_err(|e| in_field(e, "surface.peaks.from."))?;
                let d = Discrete::sample(parent.as_ref(), *n, *seed)
                    .map_err(|e| in_field(e, "surface.peaks."))?;
                Some(d.heights().to_vec())
            }
            _ => None,
        })
    }

    /// The surface-height statistics of the non-contact terms.
    pub fn heights(&self) -> Result<GaussianHeights> {
        GaussianHeights::new(self.surface.height_sigma_m).map_err(|e| match e {
            Error::InvalidInput { reason, .. } => Error::invalid("surface.height_sigma_m", reason),
            other => other,
        })
    }

    /// Contact potential φ (V); 0 when the electrostatic term is off.
    pub fn contact_potential_v(&self) -> f64 {
        self.electrostatic
            .as_ref()
            .map_or(0.0, |e| e.contact_potential_v)
    }

    /// `(V_dc − φ)²`, V²: the squared voltage of a static (DC) analysis.
    pub fn dc_volt2(&self) -> f64 {
        let v = self.voltage.dc_v - self.contact_potential_v();
        v * v
    }

    /// The non-contact cutoff of the electrostatic term: its own, else that of the
    /// intermolecular term (given or `h_e`).
    fn electrostatic_cutoff(&self) -> Option<f64> {
        let e = self.electrostatic.as_ref()?;
        e.cutoff_m.or_else(|| {
            self.intermolecular.as_ref().map(|m| {
                m.cutoff_m
                    .unwrap_or_else(|| lj_zero(m.hamaker_attractive_j, m.hamaker_repulsive_j_m6))
            })
        })
    }

    /// The enabled interface terms (only those), validated.
    pub fn interface_terms(&self) -> Result<Vec<Box<dyn InterfaceTerm>>> {
        self.validate()?;
        let mut terms: Vec<Box<dyn InterfaceTerm>> = Vec::new();
        if let Some(m) = &self.intermolecular {
            let t = Intermolecular::new(
                m.hamaker_attractive_j,
                m.hamaker_repulsive_j_m6,
                m.cutoff_m,
                self.heights()?,
                m.footprint,
                m.gap,
            )
            .map_err(|e| in_field(e, "intermolecular."))?;
            terms.push(Box::new(t));
        }
        if let Some(e) = &self.electrostatic {
            let hc = self.electrostatic_cutoff().ok_or_else(|| {
                Error::invalid(
                    "electrostatic.cutoff_m",
                    "required when the intermolecular term is off",
                )
            })?;
            let t = Electrostatic::new(
                e.dielectric_thickness_m,
                hc,
                self.heights()?,
                e.footprint,
                e.gap,
            )
            .map_err(|err| in_field(err, "electrostatic."))?;
            terms.push(Box::new(t));
        }
        if let Some(c) = &self.contact {
            let t = GreenwoodWilliamson::new(
                c.composite_modulus_pa,
                c.asperity_radius_m,
                c.asperity_density_per_m2,
                self.peaks()?,
                c.footprint,
                c.gap,
            )
            .map_err(|e| in_field(e, "contact."))?;
            let t = match self.discrete_peak_heights()? {
                Some(h) => t.with_discrete_peaks(&h),
                None => t,
            };
            terms.push(Box::new(t));
        }
        Ok(terms)
    }

    /// The lubricant menisci of the `[lubricant]` section on the asperities of `[contact]`,
    /// tabulated over [`Scene::table_range`]; `None` when the section is absent or the mobile
    /// thickness is zero (the model is then exactly that of the scene without it).
    pub fn meniscus(&self) -> Result<Option<Meniscus>> {
        match self.meniscus_term()? {
            Some(m) => Ok(Some(
                m.tabulated(self.table_range(), &self.table_options())?,
            )),
            None => Ok(None),
        }
    }

    /// The menisci of [`Scene::meniscus`] before tabulation.
    fn meniscus_term(&self) -> Result<Option<Meniscus>> {
        self.validate()?;
        let (Some(l), Some(c)) = (&self.lubricant, &self.contact) else {
            return Ok(None);
        };
        let mobile = l.mobile_thickness_m();
        if mobile <= 0.0 {
            return Ok(None);
        }
        let params = MeniscusParams {
            surface_tension: l.surface_tension_n_per_m,
            contact_angle: l.contact_angle_deg.to_radians(),
            wetting: match l.wetting {
                WettingSpec::Disk => Wetting::Disk,
                WettingSpec::Both => Wetting::Both,
            },
            mobile_thickness: mobile,
            rupture_distance: l.rupture_distance_m,
            healing_time: l.healing_time_s,
            formation_time: l.formation_time_s,
            pickup: match (l.pickup_rate_m_per_s, l.pickup_loss_time_s) {
                (Some(rate), Some(loss_time)) => Some(Pickup { rate, loss_time }),
                _ => None,
            },
        };
        let m = Meniscus::new(
            params,
            c.asperity_radius_m,
            c.asperity_density_per_m2,
            self.peaks()?,
            c.footprint,
        )
        .map_err(|e| in_field(e, "lubricant."))?;
        Ok(Some(m))
    }

    /// The accuracy and size limits of every table of the scene.
    fn table_options(&self) -> TableOptions {
        TableOptions {
            rel_tol: self.table.rel_tol,
            ..TableOptions::default()
        }
    }

    /// Range of separations `d` (m) that the force tables cover.
    ///
    /// Default: from `min(0, mean peak height) − 5 s` (s the larger of the surface-height and
    /// peak-height standard deviations; `min(0, mean peak height) − 0.1 h0` when both are zero,
    /// as for a single discrete peak), which reaches well into hard contact, up to `3 h0`. `table.d_min_m` / `table.d_max_m` override either end. Outside
    /// the range the forces are still exact (direct quadrature), only slower.
    pub fn table_range(&self) -> (f64, f64) {
        let (mut mean, mut std) = (0.0_f64, 0.0_f64);
        if self.contact.is_some() {
            if let Ok(p) = self.peaks() {
                mean = p.mean();
                std = p.std_dev();
            }
        }
        let s = self.surface.height_sigma_m.max(std);
        let lo = if s > 0.0 && s.is_finite() {
            mean.min(0.0) - 5.0 * s
        } else {
            mean.min(0.0) - 0.1 * self.nominal_clearance_m
        };
        let hi = 3.0 * self.nominal_clearance_m;
        (
            self.table.d_min_m.unwrap_or(lo),
            self.table.d_max_m.unwrap_or(hi),
        )
    }

    /// Validates the scene and tabulates its enabled interface terms.
    pub fn build_interface(&self) -> Result<InterfaceForces> {
        let terms = self.interface_terms()?;
        InterfaceForces::build(terms, self.table_range(), &self.table_options())
    }

    /// [`Scene::build_interface`] through a table cache: the tables read from `cache` when it
    /// holds them for this scene's inputs, else built and stored (see [`crate::cache`]). The
    /// forces are the same, to the bit, either way.
    ///
    /// ```no_run
    /// use hdi_tribology::{cache::TableCache, scene::Scene};
    /// let cache = TableCache::in_dir("/tmp/hdi-cache");
    /// let (forces, report) = Scene::paper().build_interface_cached(&cache)?;
    /// for n in &report.notices {
    ///     eprintln!("warning: {n}");
    /// }
    /// # Ok::<(), hdi_tribology::Error>(())
    /// ```
    pub fn build_interface_cached(
        &self,
        cache: &TableCache,
    ) -> Result<(InterfaceForces, CacheReport)> {
        let (forces, _, report) = self.tables_cached(cache)?;
        Ok((forces, report))
    }

    /// Every table of the scene (the interface forces and the lubricant menisci) through
    /// `cache`: one entry holds them all.
    pub(crate) fn tables_cached(
        &self,
        cache: &TableCache,
    ) -> Result<(InterfaceForces, Option<Meniscus>, CacheReport)> {
        let key = self.table_key()?;
        let build = || -> Result<SceneTables> { Ok((self.build_interface()?, self.meniscus()?)) };
        let decode = |payload: &[u8]| self.decode_tables(payload);
        let ((forces, meniscus), report) =
            cache.get_or_build(&key, decode, build, encode_tables)?;
        Ok((forces, meniscus, report))
    }

    /// The scene's tables from a payload of [`encode_tables`], every index checked.
    pub(crate) fn decode_tables(&self, payload: &[u8]) -> Result<SceneTables> {
        let mut r = Reader::new(payload);
        let terms = self.interface_terms()?;
        let forces = InterfaceForces::decode_tables(terms, self.table_range(), &mut r)?;
        let meniscus = match (r.bool()?, self.meniscus_term()?) {
            (true, Some(m)) if m.tabulates() => Some(m.with_table(Table::decode(&mut r)?)),
            (false, None) => None,
            (false, Some(m)) if !m.tabulates() => Some(m),
            _ => return Err(malformed("a meniscus table that does not fit the menisci")),
        };
        if !r.is_done() {
            return Err(malformed("bytes left over after the tables"));
        }
        Ok((forces, meniscus))
    }

    /// The key of the scene's tables in a [`TableCache`]: exactly the fields the tabulated
    /// functions, the table range and the table options are made from, as JSON (each number
    /// written so that it reads back to the same bits).
    fn table_key(&self) -> Result<String> {
        self.validate()?;
        #[derive(Serialize)]
        struct Electrostatic<'a> {
            dielectric_thickness_m: f64,
            cutoff_m: Option<f64>,
            footprint: &'a Footprint,
            gap: GapReference,
        }
        #[derive(Serialize)]
        struct Inputs<'a> {
            table_range_m: (f64, f64),
            rel_tol: f64,
            abs_tol: f64,
            max_nodes: usize,
            height_sigma_m: Option<f64>,
            peaks: Option<&'a PeakModel>,
            intermolecular: Option<&'a IntermolecularSpec>,
            electrostatic: Option<Electrostatic<'a>>,
            contact: Option<&'a ContactSpec>,
            lubricant: Option<&'a LubricantSpec>,
        }
        let opts = self.table_options();
        let non_contact = self.intermolecular.is_some() || self.electrostatic.is_some();
        let inputs = Inputs {
            table_range_m: self.table_range(),
            rel_tol: opts.rel_tol,
            abs_tol: opts.abs_tol,
            max_nodes: opts.max_nodes,
            height_sigma_m: non_contact.then_some(self.surface.height_sigma_m),
            peaks: self.contact.as_ref().map(|_| &self.surface.peaks),
            intermolecular: self.intermolecular.as_ref(),
            // The contact potential only shifts the voltage: not in the tables.
            electrostatic: self.electrostatic.as_ref().map(|e| Electrostatic {
                dielectric_thickness_m: e.dielectric_thickness_m,
                cutoff_m: self.electrostatic_cutoff(),
                footprint: &e.footprint,
                gap: e.gap,
            }),
            contact: self.contact.as_ref(),
            lubricant: self.meniscus_term()?.and(self.lubricant.as_ref()),
        };
        serde_json::to_string(&inputs).map_err(|e| Error::invalid("table cache key", e.to_string()))
    }

    /// The air bearing.
    pub fn build_air_bearing(&self) -> Result<Box<dyn AirBearing>> {
        self.air_bearing.build()
    }

    /// The bearing the structure takes its matrices from: the `reynolds` air bearing when
    /// `structure.from_bearing = true`, else `None`. The bearing is solved once per process
    /// ([`ReynoldsBearing::of_spec`]): after the scene's validation this solves nothing.
    ///
    /// # Errors
    /// `structure.from_bearing` with an air bearing that is not `reynolds`; the air bearing's
    /// own errors.
    ///
    /// ```
    /// use hdi_tribology::scene::Scene;
    /// assert!(Scene::paper().structure_bearing()?.is_none());
    /// # Ok::<(), hdi_tribology::Error>(())
    /// ```
    pub fn structure_bearing(&self) -> Result<Option<ReynoldsBearing>> {
        if !self.structure.from_bearing() {
            return Ok(None);
        }
        match self.air_bearing.bearing_spec()? {
            Some(spec) => Ok(Some(ReynoldsBearing::of_spec(&spec)?)),
            None => Err(self.no_bearing_for_structure()),
        }
    }

    /// The error of `structure.from_bearing` on an air bearing that is not solved from the
    /// slider's geometry.
    pub(crate) fn no_bearing_for_structure(&self) -> Error {
        let model = self.air_bearing.name();
        Error::invalid(
            "structure.from_bearing",
            format!(
                "takes the pitch stiffness and damping from the air bearing solved from the \
                 slider's geometry, which needs air_bearing.model = \"reynolds\", not \
                 \"{model}\"; or give the four matrix entries and trailing_edge_m"
            ),
        )
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::force::{Gaps, StatefulTerm};
    use crate::scene::LubricantSpec;

    /// The paper scene with the intermolecular term on the pad gap (separate, merged tables, no
    /// fused one) and lubricant menisci (a table of their own).
    fn every_kind_of_table() -> Scene {
        let mut s = Scene::paper();
        if let Some(m) = s.intermolecular.as_mut() {
            m.gap = GapReference::Pad;
        }
        s.lubricant = Some(LubricantSpec {
            total_thickness_m: 1.5e-9,
            bonded_thickness_m: 0.5e-9,
            surface_tension_n_per_m: 0.025,
            contact_angle_deg: 0.0,
            wetting: WettingSpec::Disk,
            healing_time_s: 1e-5,
            formation_time_s: 1e-7,
            rupture_distance_m: None,
            pickup_rate_m_per_s: None,
            pickup_loss_time_s: None,
        });
        s
    }

    /// Every value the tables give on a grid over and beyond the table range, as text (Rust
    /// prints each number so that it reads back to the same bits).
    fn fingerprint(scene: &Scene, (forces, meniscus): &SceneTables) -> String {
        let (lo, hi) = scene.table_range();
        let mut out = String::new();
        for i in 0..=400 {
            let d = lo - 0.05 * (hi - lo) + 1.1 * (hi - lo) * f64::from(i) / 400.0;
            let g = Gaps {
                bulge: d,
                pad: d + 0.3e-9,
            };
            out += &format!(
                "{:?}{:?}{:?}{:?}",
                forces.evaluate(g),
                forces.values(g, 0.7),
                forces.breakdown(g, 0.7),
                forces.real_contact_area(g)
            );
            if let Some(m) = meniscus {
                let mut x = vec![0.0; m.states()];
                m.equilibrium(g, &mut x);
                out += &format!("{:?}", m.force(g, &x));
            }
        }
        out + &forces.table_nodes().to_string()
    }

    #[test]
    fn tables_read_back_are_the_tables_built_and_bad_payloads_fail_cleanly() {
        let scene = every_kind_of_table();
        let built = (scene.build_interface().unwrap(), scene.meniscus().unwrap());
        assert!(built.1.as_ref().is_some_and(|m| m.table().is_some()));
        let payload = encode_tables(&built);
        let read = scene.decode_tables(&payload).unwrap();
        assert_eq!(encode_tables(&read), payload);
        assert_eq!(fingerprint(&scene, &read), fingerprint(&scene, &built));

        // Every cut short is refused.
        for k in 0..64 {
            let len = payload.len() * k / 64;
            assert!(
                scene.decode_tables(&payload[..len]).is_err(),
                "cut at {len}"
            );
        }
        // A flipped bit (as if the checksum had been fooled) either fails to decode or gives
        // tables whose every look-up stays inside them: no panic.
        let mut refused = 0;
        let step = payload.len() / 397;
        for (n, at) in (0..payload.len()).step_by(step).enumerate() {
            let mut bad = payload.clone();
            bad[at] ^= 1 << (n % 8);
            match scene.decode_tables(&bad) {
                Err(_) => refused += 1,
                Ok(t) => drop(fingerprint(&scene, &t)),
            }
        }
        assert!(refused > 0);
        // Tables of another scene do not decode for this one (other terms, other range).
        let paper = Scene::paper();
        let other = encode_tables(&(paper.build_interface().unwrap(), None));
        assert!(scene.decode_tables(&other).is_err());
    }

    #[test]
    fn the_key_holds_what_the_tables_depend_on_and_nothing_else() {
        let paper = Scene::paper();
        let key = paper.table_key().unwrap();
        let same = |f: &dyn Fn(&mut Scene)| {
            let mut s = paper.clone();
            s.surface.independent_peak_sigma = true;
            f(&mut s);
            s.table_key().unwrap() == key
        };
        // Not in the tables: voltages, heater, structure, solver, names.
        assert!(same(&|s| s.voltage.dc_v = 3.0));
        assert!(same(&|s| s
            .electrostatic
            .as_mut()
            .unwrap()
            .contact_potential_v = 0.4));
        assert!(same(&|s| s.heater.efficiency_m_per_w = 2e-7));
        assert!(same(&|s| s.solver.rtol = 1e-8));
        assert!(same(&|s| s.name = "other".into()));
        // In them: every term's parameters, the surface, the range and the accuracy.
        assert!(!same(&|s| s.nominal_clearance_m = 1.1e-8));
        assert!(!same(&|s| s.surface.height_sigma_m = 0.8e-9));
        assert!(!same(&|s| s.table.rel_tol = 1e-8));
        assert!(!same(&|s| s.table.d_max_m = Some(2e-8)));
        assert!(!same(
            &|s| s.contact.as_mut().unwrap().asperity_radius_m = 2e-7
        ));
        assert!(!same(
            &|s| s.intermolecular.as_mut().unwrap().gap = GapReference::Pad
        ));
        assert!(!same(&|s| s
            .electrostatic
            .as_mut()
            .unwrap()
            .dielectric_thickness_m = 1e-9));
        assert!(!same(&|s| s.contact = None));
        assert!(!same(&|s| *s = every_kind_of_table()));
        // A number one ulp away is another key.
        assert!(!same(&|s| {
            s.contact.as_mut().unwrap().composite_modulus_pa =
                f64::from_bits(s.contact.as_ref().unwrap().composite_modulus_pa.to_bits() + 1)
        }));
    }
}
