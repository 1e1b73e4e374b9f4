//! [`InterfaceForces`]: every enabled term tabulated once, merged by time dependence and gap, for a
//! hot path of a few table look-ups.

use std::sync::Arc;

use serde::Serialize;

use super::fused::Fused;
use super::{Coupling, GapReference, InterfaceTerm, TermKind};
use crate::cache::codec::{malformed, Reader, Writer};
use crate::quadrature::{Span, Table, TableOptions};
use crate::{Error, Result};

/// The two gaps a term may see: at the bulge (`d`) and at the pad (`d + δ`), both in m.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Gaps {
    /// Bulge gap `d`, m.
    pub bulge: f64,
    /// Pad gap `d + δ`, m.
    pub pad: f64,
}

impl Gaps {
    /// Both gaps equal to `d` (no pad terms, or no protrusion).
    pub fn same(d: f64) -> Self {
        Gaps { bulge: d, pad: d }
    }
}

/// A value and its partial derivatives with respect to the bulge gap and the pad gap.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct ForceEval {
    /// The value (N, or N/V²).
    pub value: f64,
    /// ∂value/∂d_bulge.
    pub d_bulge: f64,
    /// ∂value/∂d_pad.
    pub d_pad: f64,
}

/// The three hot-path sums at one point, from [`InterfaceForces::evaluate`].
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct HotForces {
    /// As [`InterfaceForces::static_part`].
    pub static_part: ForceEval,
    /// As [`InterfaceForces::per_volt2_part`].
    pub per_volt2: ForceEval,
    /// As [`InterfaceForces::contact`].
    pub contact: ForceEval,
}

/// The values of [`InterfaceForces::values`]: what an ODE's right-hand side reads at one point.
///
/// ```no_run
/// # fn main() -> hdi_tribology::Result<()> {
/// use hdi_tribology::{force::{Gaps, HotValues}, scene::Scene};
/// let forces = Scene::paper().build_interface()?;
/// let HotValues { interface, contact, area } = forces.values(Gaps::same(5e-9), 0.0);
/// assert!(interface < 0.0 && contact >= 0.0 && area >= 0.0); // attraction, little contact
/// # Ok(()) }
/// ```
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct HotValues {
    /// Interface force `F_static + V² G_e` (N).
    pub interface: f64,
    /// Contact force (N), never negative.
    pub contact: f64,
    /// Real contact area (m²), never negative.
    pub area: f64,
}

/// The one home of summing by coupling: a static part plus `V²` times the per-V² part.
#[inline]
pub(crate) fn by_coupling(static_part: f64, per_volt2: f64, volt2: f64) -> f64 {
    static_part + volt2 * per_volt2
}

/// Every force by kind at one point, SI (N, m²), positive = away from the disk.
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize)]
pub struct Breakdown {
    /// Intermolecular force, N.
    #[serde(rename = "intermolecular_n")]
    pub intermolecular: f64,
    /// Asperity contact force, N.
    #[serde(rename = "contact_n")]
    pub contact: f64,
    /// Electrostatic force per V², N/V².
    #[serde(rename = "electrostatic_per_volt2_n_per_v2")]
    pub electrostatic_per_volt2: f64,
    /// Electrostatic force at the given V², N.
    #[serde(rename = "electrostatic_n")]
    pub electrostatic: f64,
    /// Terms of kind [`TermKind::Other`], N.
    #[serde(rename = "other_n")]
    pub other: f64,
    /// Real contact area, m².
    #[serde(rename = "real_contact_area_m2")]
    pub real_contact_area: f64,
    /// Sum of the forces, N.
    #[serde(rename = "total_n")]
    pub total: f64,
}

/// What the interface forces are at separations outside their tables
/// ([`InterfaceForces::with_outside_tables`]).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum OutsideTables {
    /// The exact sum of the terms by direct quadrature: correct everywhere, but on the paper
    /// scene one evaluation below the tables costs about 0.2 ms, some two thousand look-ups.
    #[default]
    Exact,
    /// Not a number. An ODE step whose trial state leaves the tables then fails as non-finite
    /// and is shortened, so no right-hand side costs more than a look-up; a run whose solution
    /// itself leaves the tables ends in an error. For runs whose cost per step must be bounded
    /// (the drive's bounded mode, `DriveOptions::steps_per_period`).
    Refused,
}

/// A sum of terms tabulated over one gap, split at the terms' kinks, with exact fallback.
#[derive(Debug)]
struct Tabulated {
    members: Vec<usize>,
    area: bool,
    /// Interior cuts, ascending: segment k covers [cuts[k-1], cuts[k]).
    cuts: Vec<f64>,
    segments: Vec<Table>,
}

/// Where a merged table takes its values from.
enum Source<'a> {
    /// Direct evaluation of the member terms.
    Exact,
    /// The sum of already built tables over the same segments (their nodes are a subset of the
    /// merged table's dyadic grid, so the sum is reproduced to rounding).
    Parts(&'a [Arc<Tabulated>]),
}

impl Tabulated {
    fn exact_one(&self, terms: &[Box<dyn InterfaceTerm>], d: f64) -> Result<(f64, f64)> {
        let (mut v, mut s) = (0.0, 0.0);
        for &i in &self.members {
            let (a, b) = if self.area {
                terms[i].real_contact_area_and_slope(d)?
            } else {
                let f = terms[i].force(d)?;
                (f.value, f.slope)
            };
            v += a;
            s += b;
        }
        Ok((v, s))
    }

    /// Tabulates the sum of `members` on the segments between consecutive `edges`.
    fn build(
        terms: &[Box<dyn InterfaceTerm>],
        members: Vec<usize>,
        area: bool,
        edges: &[f64],
        opts: &TableOptions,
        source: Source<'_>,
    ) -> Result<Self> {
        let mut me = Tabulated {
            members,
            area,
            cuts: edges[1..edges.len() - 1].to_vec(),
            segments: Vec::with_capacity(edges.len() - 1),
        };
        let names: Vec<String> = me
            .members
            .iter()
            .map(|&i| terms[i].name().to_string())
            .collect();
        for (k, w) in edges.windows(2).enumerate() {
            let (a, b) = (w[0], w[1]);
            // At an interior kink evaluate one ulp inside the segment, so that each piece sees the
            // one-sided limit of a function that jumps there (smooth surface, flat footprint).
            let a_in = if k == 0 { a } else { next_toward(a, b) };
            let b_in = if k + 2 == edges.len() {
                b
            } else {
                next_toward(b, a)
            };
            let f = |x: f64| -> Result<(f64, f64)> {
                let x = x.clamp(a_in, b_in);
                match source {
                    Source::Exact => me.exact_one(terms, x),
                    Source::Parts(parts) => {
                        let (mut v, mut s) = (0.0, 0.0);
                        for p in parts {
                            let (pv, ps) = match p.lookup(x) {
                                Some(e) => e,
                                None => p.exact_one(terms, x)?,
                            };
                            v += pv;
                            s += ps;
                        }
                        Ok((v, s))
                    }
                }
            };
            let table = Table::build(f, a, b, opts).map_err(|e| {
                Error::from(super::ForceError::Table {
                    area,
                    terms: names.clone(),
                    source: e.into(),
                })
            })?;
            me.segments.push(table);
        }
        Ok(me)
    }

    #[inline]
    fn lookup(&self, d: f64) -> Option<(f64, f64)> {
        self.segment(d).eval(d)
    }

    /// The value of [`Tabulated::lookup`] alone.
    #[inline]
    fn lookup_value(&self, d: f64) -> Option<f64> {
        self.segment(d).value(d)
    }

    /// The segment holding `d`.
    #[inline]
    fn segment(&self, d: f64) -> &Table {
        if self.segments.len() == 1 {
            return &self.segments[0];
        }
        // Right-continuous at the cuts, like the terms themselves (d ≥ h_c counts as non-contact).
        &self.segments[self.cuts.partition_point(|&c| c <= d)]
    }

    /// Bounds of [`Tabulated::lookup`]'s value and slope at every `d` in `[a, b]`, or `None`
    /// where a point of `[a, b]` lies outside the tables: the hull over the segments that the
    /// points of `[a, b]` can be given.
    fn bounds(&self, a: f64, b: f64) -> Option<(Span, Span)> {
        if self.segments.len() == 1 {
            return self.segments[0].bounds(a, b);
        }
        let segment = |d: f64| self.cuts.partition_point(|&c| c <= d);
        let mut out: Option<(Span, Span)> = None;
        for t in &self.segments[segment(a)..=segment(b)] {
            let (lo, hi) = t.range();
            let (x, y) = (a.max(lo), b.min(hi));
            if x > y {
                continue;
            }
            let (v, s) = t.bounds(x, y)?;
            out = Some(match out {
                Some((ov, os)) => (ov.hull(v), os.hull(s)),
                None => (v, s),
            });
        }
        out
    }

    /// Table look-up; outside the range the exact sum of `terms` (NaN without them, or if that
    /// fails).
    #[inline]
    fn eval(&self, terms: Exact<'_>, d: f64) -> (f64, f64) {
        match self.lookup(d) {
            Some(v) => v,
            None => fallback(self, terms, d),
        }
    }
}

/// The terms whose exact sum a look-up outside the tables evaluates; `None` where the forces
/// refuse to ([`OutsideTables::Refused`]).
type Exact<'a> = Option<&'a [Box<dyn InterfaceTerm>]>;

/// The exact sum outside the tables, NaN without the terms (kept out of line: the hot path stays
/// small).
#[cold]
#[inline(never)]
fn fallback(tab: &Tabulated, terms: Exact<'_>, d: f64) -> (f64, f64) {
    terms
        .and_then(|t| tab.exact_one(t, d).ok())
        .unwrap_or((f64::NAN, f64::NAN))
}

/// A table on the hot path: a single-segment table is held by value, saving the pointer chase
/// through the shared [`Tabulated`].
#[derive(Clone, Debug)]
struct Slot {
    single: Option<Table>,
    tab: Arc<Tabulated>,
}

impl Slot {
    fn new(tab: Arc<Tabulated>) -> Self {
        let single = match tab.segments.as_slice() {
            [only] => Some(only.clone()),
            _ => None,
        };
        Slot { single, tab }
    }

    #[inline]
    fn eval(&self, terms: Exact<'_>, d: f64) -> (f64, f64) {
        let hit = match &self.single {
            Some(t) => t.eval(d),
            None => self.tab.lookup(d),
        };
        match hit {
            Some(v) => v,
            None => fallback(&self.tab, terms, d),
        }
    }

    /// The value of [`Slot::eval`] alone (the same number).
    #[inline]
    fn value(&self, terms: Exact<'_>, d: f64) -> f64 {
        let hit = match &self.single {
            Some(t) => t.value(d),
            None => self.tab.lookup_value(d),
        };
        match hit {
            Some(v) => v,
            None => fallback(&self.tab, terms, d).0,
        }
    }
}

impl Slot {
    /// Bounds of [`Slot::eval`] over `[a, b]` where it reads the tables alone.
    fn bounds(&self, a: f64, b: f64) -> Option<(Span, Span)> {
        match &self.single {
            Some(t) => t.bounds(a, b),
            None => self.tab.bounds(a, b),
        }
    }
}

/// Bounds of the interface force of [`crate::model::SliderModel::interface_force`] and of the
/// contact force of [`InterfaceForces::contact`] over a stretch of bulge gaps (no term on the
/// pad gap), each as the tables give them, rounding included.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct BulgeBounds {
    /// `F_static + V² G_e` (N).
    pub force: Span,
    /// Its slope `∂F/∂d` (N/m).
    pub slope: Span,
    /// The contact force (N).
    pub contact: Span,
}

/// A contact force (and area) is never negative: an interpolation undershoot below zero, of the
/// order of the table's absolute tolerance, is clamped to zero with zero slope.
fn non_negative(e: ForceEval) -> ForceEval {
    if e.value < 0.0 {
        ForceEval::default()
    } else {
        e
    }
}

fn next_toward(x: f64, toward: f64) -> f64 {
    let step = (x.abs() * f64::EPSILON).max(f64::MIN_POSITIVE);
    if toward > x {
        x + step
    } else {
        x - step
    }
}

type ArcGap = [Option<Arc<Tabulated>>; 2];

/// The codes of a term's kind, coupling and gap in a cache payload: their place in these lists.
const KINDS: [TermKind; 4] = [
    TermKind::Intermolecular,
    TermKind::Contact,
    TermKind::Electrostatic,
    TermKind::Other,
];
const COUPLINGS: [Coupling; 2] = [Coupling::Static, Coupling::PerVoltSquared];
const GAPS: [GapReference; 2] = [GapReference::Bulge, GapReference::Pad];

/// The code of `x` in `list` (which holds it).
fn code<T: PartialEq>(list: &[T], x: &T) -> u8 {
    list.iter().position(|y| y == x).unwrap_or(0) as u8
}

/// The item of `list` of a code read from `r`.
fn decode_code<T: Copy>(list: &[T], r: &mut Reader<'_>) -> Result<T> {
    let c = r.u8()?;
    list.get(usize::from(c))
        .copied()
        .ok_or_else(|| malformed(format!("a code {c} of {} choices", list.len())))
}
type PerGap = [Option<Slot>; 2];

/// Checks the arguments of [`InterfaceForces::build`]: a finite range `d_min < d_max`, and
/// contact terms static.
fn check_build(terms: &[Box<dyn InterfaceTerm>], (lo, hi): (f64, f64)) -> Result<()> {
    if !(lo.is_finite() && hi.is_finite() && lo < hi) {
        return Err(Error::invalid(
            "table range",
            format!("needs finite d_min < d_max, got ({lo}, {hi})"),
        ));
    }
    for t in terms {
        if t.kind() == TermKind::Contact && t.coupling() != Coupling::Static {
            return Err(Error::invalid(
                format!("term {}", t.name()),
                "contact terms must be static",
            ));
        }
    }
    Ok(())
}

/// The indices of the terms that `pick` picks.
fn members(
    terms: &[Box<dyn InterfaceTerm>],
    pick: impl Fn(&dyn InterfaceTerm) -> bool,
) -> Vec<usize> {
    (0..terms.len())
        .filter(|&i| pick(terms[i].as_ref()))
        .collect()
}

/// The segment edges of the tables on `gap` over `range`: its ends and the kinks of the terms on
/// that gap inside it, each once.
fn table_edges(terms: &[Box<dyn InterfaceTerm>], gap: GapReference, range: (f64, f64)) -> Vec<f64> {
    let (lo, hi) = range;
    let mut cuts: Vec<f64> = terms
        .iter()
        .filter(|t| t.gap() == gap)
        .flat_map(|t| t.kinks())
        .filter(|&k| k.is_finite() && k > lo && k < hi)
        .collect();
    cuts.sort_by(f64::total_cmp);
    cuts.dedup_by(|a, b| (*a - *b).abs() <= 1e-12 * b.abs().max(1e-30));
    let mut edges = vec![lo];
    edges.extend(cuts);
    edges.push(hi);
    edges
}

/// A table per gap, kind and coupling that some term has, of those terms.
type KindTables = Vec<(TermKind, Coupling, GapReference, Arc<Tabulated>)>;

/// The tables of each gap, kind and coupling with terms, over the `edges` of their gap.
fn per_kind_tables(
    terms: &[Box<dyn InterfaceTerm>],
    edges: &[Vec<f64>; 2],
    opts: &TableOptions,
) -> Result<KindTables> {
    let mut by_kind = Vec::new();
    for gap in GAPS {
        for kind in KINDS {
            for coupling in COUPLINGS {
                let m = members(terms, |t| {
                    t.gap() == gap && t.kind() == kind && t.coupling() == coupling
                });
                if !m.is_empty() {
                    let e = &edges[gap.index()];
                    let tab = Tabulated::build(terms, m, false, e, opts, Source::Exact)?;
                    by_kind.push((kind, coupling, gap, Arc::new(tab)));
                }
            }
        }
    }
    Ok(by_kind)
}

/// The tables the hot path reads on each gap: the static and per-V² sums, the contact force and
/// the real contact area.
struct GapTables {
    static_part: ArcGap,
    per_volt2: ArcGap,
    contact: ArcGap,
    area: ArcGap,
}

impl GapTables {
    /// The sums from the per-kind tables `by_kind`, the contact force's table among them, and the
    /// real contact area tabulated to `area_opts`.
    fn build(
        terms: &[Box<dyn InterfaceTerm>],
        by_kind: &KindTables,
        edges: &[Vec<f64>; 2],
        opts: &TableOptions,
        area_opts: &TableOptions,
    ) -> Result<Self> {
        let mut me = GapTables {
            static_part: [None, None],
            per_volt2: [None, None],
            contact: [None, None],
            area: [None, None],
        };
        for gap in GAPS {
            let g = gap.index();
            for (coupling, slot) in [
                (Coupling::Static, &mut me.static_part[g]),
                (Coupling::PerVoltSquared, &mut me.per_volt2[g]),
            ] {
                let m = members(terms, |t| t.gap() == gap && t.coupling() == coupling);
                if m.is_empty() {
                    continue;
                }
                // A single kind reuses its table; several kinds are summed from theirs. Summing
                // tables (not re-integrating the sum) keeps each term's accuracy where the terms
                // cancel: a direct table of the sum would chase quadrature rounding there.
                let parts: Vec<Arc<Tabulated>> = by_kind
                    .iter()
                    .filter(|(_, c, gp, _)| *c == coupling && *gp == gap)
                    .map(|(_, _, _, t)| Arc::clone(t))
                    .collect();
                *slot = Some(if parts.len() == 1 {
                    Arc::clone(&parts[0])
                } else {
                    let e = &edges[g];
                    Arc::new(Tabulated::build(
                        terms,
                        m,
                        false,
                        e,
                        opts,
                        Source::Parts(&parts),
                    )?)
                });
            }
            me.contact[g] = by_kind
                .iter()
                .find(|(k, _, gp, _)| *k == TermKind::Contact && *gp == gap)
                .map(|(_, _, _, t)| Arc::clone(t));
            let m = members(terms, |t| t.gap() == gap && t.has_contact_area());
            if !m.is_empty() {
                let tab = Tabulated::build(terms, m, true, &edges[g], area_opts, Source::Exact)?;
                me.area[g] = Some(Arc::new(tab));
            }
        }
        Ok(me)
    }
}

/// All enabled terms, tabulated over the separation.
///
/// Static terms are merged into one table per gap reference in use, voltage-driven terms likewise;
/// the contact force and the real contact area have their own tables (friction and the contact
/// indicator need them every step), and each kind has one for [`InterfaceForces::breakdown`].
/// Tables are piecewise cubic Hermite in value and slope, built to the accuracy of
/// [`TableOptions`] against the terms' direct quadrature (the area tables use an absolute tolerance
/// 1e-8 times the force one, in m² instead of N). A merged table of several kinds is the sum of
/// the per-kind tables, re-tabulated on their common node grid: it is accurate to
/// `rel_tol · Σ|F_i| + abs_tol` even where the terms cancel. Tables are split where a term reports
/// a kink ([`InterfaceTerm::kinks`]).
///
/// Outside the table range every hot-path function falls back to the exact term evaluation (slow
/// but correct; nothing is clamped), unless the forces refuse it
/// ([`InterfaceForces::with_outside_tables`]). The hot-path functions are infallible: if that
/// fallback fails, or is refused, they return NaN, which an ODE solver reports as a non-finite
/// state.
///
/// ```
/// use hdi_tribology::force::{Gaps, InterfaceForces};
/// use hdi_tribology::scene::Scene;
/// # fn main() -> hdi_tribology::Result<()> {
/// let scene = Scene::paper();
/// let forces = scene.build_interface()?;
/// let g = Gaps::same(2e-9);
/// let f = forces.static_part(g).value + 1.0 * forces.per_volt2_part(g).value;
/// let b = forces.breakdown(g, 1.0);
/// assert!((f - b.total).abs() <= 1e-8 * f.abs());
/// assert!(b.intermolecular < 0.0 && b.electrostatic < 0.0 && b.contact > 0.0);
/// // the hot path: all three sums from one look-up
/// let hot = forces.evaluate(g);
/// assert!((hot.contact.value - b.contact).abs() <= 1e-8 * b.contact);
/// # Ok(()) }
/// ```
#[derive(Clone, Debug)]
pub struct InterfaceForces {
    terms: Arc<Vec<Box<dyn InterfaceTerm>>>,
    range: (f64, f64),
    static_part: PerGap,
    per_volt2: PerGap,
    contact: PerGap,
    area: PerGap,
    by_kind: KindTables,
    /// Static, per-V² and contact sums and the real contact area on one grid.
    fused: Option<Arc<Fused<4>>>,
    /// The same, split at the kinks, where the tables on the bulge gap have kinks (never with
    /// `fused`).
    kinked: Option<Arc<Fused<4, true>>>,
    /// Whether the fused table's fourth function is the real contact area (else it is zero and
    /// the area comes from its own table).
    fused_area: bool,
    /// The forces outside the tables.
    outside: OutsideTables,
}

impl InterfaceForces {
    /// Tabulates `terms` over `range` = (d_min, d_max) (m; both gap references use it).
    pub fn build(
        terms: Vec<Box<dyn InterfaceTerm>>,
        range: (f64, f64),
        opts: &TableOptions,
    ) -> Result<Self> {
        check_build(&terms, range)?;
        let area_opts = TableOptions {
            abs_tol: opts.abs_tol * 1e-8,
            ..*opts
        };
        // Every table on one gap shares the same cuts (the union of the kinks of its terms), so
        // that merged tables can be summed from per-kind tables node for node.
        let edges = GAPS.map(|gap| table_edges(&terms, gap, range));
        let by_kind = per_kind_tables(&terms, &edges, opts)?;
        let merged = GapTables::build(&terms, &by_kind, &edges, opts, &area_opts)?;
        let hot = |a: ArcGap| a.map(|t| t.map(Slot::new));
        let mut me = InterfaceForces {
            terms: Arc::new(terms),
            range,
            static_part: hot(merged.static_part),
            per_volt2: hot(merged.per_volt2),
            contact: hot(merged.contact),
            area: hot(merged.area),
            by_kind,
            fused: None,
            kinked: None,
            fused_area: false,
            outside: OutsideTables::Exact,
        };
        me.fuse(opts, &area_opts);
        Ok(me)
    }

    /// Fuses the three hot sums when everything sits on the bulge gap in one smooth piece, and
    /// the real contact area with them (to its own tolerance `area_opts`) when it does too: a
    /// right-hand side with frictional heating then reads everything from one interval.
    fn fuse(&mut self, opts: &TableOptions, area_opts: &TableOptions) {
        let smooth = |p: &PerGap| p[0].as_ref().is_none_or(|s| s.single.is_some());
        if self.uses_pad_gap() {
            return;
        }
        if !smooth(&self.static_part) || !smooth(&self.per_volt2) || !smooth(&self.contact) {
            self.fuse_kinked();
            return;
        }
        let me = &*self;
        let (lo, hi) = me.range;
        let area_fusable = me.area[0].as_ref().is_some_and(|s| s.single.is_some());
        let build = |with_area: bool| {
            Fused::build(
                |d| {
                    let g = Gaps::same(d);
                    let area = if with_area {
                        me.sum(&me.area, g)
                    } else {
                        ForceEval::default()
                    };
                    let e = [me.static_part(g), me.per_volt2_part(g), me.contact(g), area];
                    e.map(|x| (x.value, x.d_bulge))
                },
                lo,
                hi,
                [
                    (opts.rel_tol, opts.abs_tol),
                    (opts.rel_tol, opts.abs_tol),
                    (opts.rel_tol, opts.abs_tol),
                    (area_opts.rel_tol, area_opts.abs_tol),
                ],
            )
        };
        // Should the area need more nodes than the budget, the forces are fused alone.
        let (fused, with_area) = match area_fusable.then(|| build(true)).flatten() {
            Some(f) => (Some(f), true),
            None => (build(false), false),
        };
        self.fused_area = with_area;
        self.fused = fused.map(Arc::new);
    }

    /// Fuses the hot sums of tables split at kinks (all on the bulge gap, one set of cuts) on
    /// the union of their grids, segment by segment: the same piecewise cubics to rounding, one
    /// look-up instead of four.
    fn fuse_kinked(&mut self) {
        let tab = |p: &PerGap| p[0].as_ref().map(|s| Arc::clone(&s.tab));
        let tabs = [
            tab(&self.static_part),
            tab(&self.per_volt2),
            tab(&self.contact),
            tab(&self.area),
        ];
        let Some(first) = tabs.iter().flatten().next() else {
            return;
        };
        let cuts = first.cuts.clone();
        if tabs.iter().flatten().any(|t| t.cuts != cuts) {
            return;
        }
        let parts = std::array::from_fn(|k| tabs[k].as_ref().map(|t| t.segments.as_slice()));
        let (lo, hi) = self.range;
        self.kinked = Fused::from_tables(lo, hi, &cuts, parts).map(Arc::new);
        self.fused_area = self.kinked.is_some() && tabs[3].is_some();
    }

    /// The four values of whichever fused table there is at bulge gap `d`; `None` without one
    /// or outside it.
    #[inline(always)]
    fn fused_values(&self, d: f64) -> Option<[f64; 4]> {
        match &self.fused {
            Some(f) => f.values(d),
            None => self.kinked.as_ref().and_then(|k| k.values(d)),
        }
    }

    /// The four (value, slope) pairs of whichever fused table there is at bulge gap `d`.
    #[inline(always)]
    fn fused_eval(&self, d: f64) -> Option<[(f64, f64); 4]> {
        match &self.fused {
            Some(f) => f.eval(d),
            None => self.kinked.as_ref().and_then(|k| k.eval(d)),
        }
    }

    /// Bounds of the first two of [`Self::fused_eval`] over `[a, b]`: `None` without a fused
    /// table, `Some(None)` where `[a, b]` leaves it.
    fn fused_bounds(&self, a: f64, b: f64) -> Option<Option<[(Span, Span); 2]>> {
        match (&self.fused, &self.kinked) {
            (Some(f), _) => Some(f.bounds(a, b)),
            (None, Some(k)) => Some(k.bounds(a, b)),
            (None, None) => None,
        }
    }

    /// The value of [`InterfaceForces::sum`] alone (the same number).
    #[inline]
    fn sum_value(&self, slots: &PerGap, g: Gaps) -> f64 {
        let mut v = 0.0;
        if let Some(t) = &slots[0] {
            v += t.value(self.exact(), g.bulge);
        }
        if let Some(t) = &slots[1] {
            v += t.value(self.exact(), g.pad);
        }
        v
    }

    #[inline]
    fn sum(&self, slots: &PerGap, g: Gaps) -> ForceEval {
        let mut e = ForceEval::default();
        if let Some(t) = &slots[0] {
            let (v, s) = t.eval(self.exact(), g.bulge);
            e.value += v;
            e.d_bulge = s;
        }
        if let Some(t) = &slots[1] {
            let (v, s) = t.eval(self.exact(), g.pad);
            e.value += v;
            e.d_pad = s;
        }
        e
    }

    /// Sum of the static terms (N) and its partial derivatives. Hot path.
    #[inline]
    pub fn static_part(&self, g: Gaps) -> ForceEval {
        self.sum(&self.static_part, g)
    }

    /// Sum of the voltage-driven terms per V² (N/V²) and its partial derivatives. Hot path.
    #[inline]
    pub fn per_volt2_part(&self, g: Gaps) -> ForceEval {
        self.sum(&self.per_volt2, g)
    }

    /// Contact force only (N; included in [`InterfaceForces::static_part`]). Hot path. Never
    /// negative: where the force is below the table's absolute tolerance an interpolation
    /// undershoot is clamped to zero (with zero slope).
    #[inline]
    pub fn contact(&self, g: Gaps) -> ForceEval {
        non_negative(self.sum(&self.contact, g))
    }

    /// [`InterfaceForces::static_part`], [`InterfaceForces::per_volt2_part`] and
    /// [`InterfaceForces::contact`] together. Hot path: when every term sits on the bulge gap in
    /// one smooth piece, the three sums share one table grid (built from the separate tables to
    /// the same tolerance), so this costs one look-up instead of three.
    #[inline]
    pub fn evaluate(&self, g: Gaps) -> HotForces {
        self.evaluate_with(g, true, true)
    }

    /// The static and per-V² sums of [`InterfaceForces::evaluate`] alone: where there is no
    /// fused table, the contact force's look-up is left out (the interface force needs the two
    /// sums only; the contact force is part of the static one), and so is the per-V² look-up
    /// when `voltage` is false (it is then zero).
    #[inline]
    pub fn coupled_sums(&self, g: Gaps, voltage: bool) -> (ForceEval, ForceEval) {
        let h = self.evaluate_with(g, false, voltage);
        (h.static_part, h.per_volt2)
    }

    /// [`InterfaceForces::evaluate`], the separate contact and per-V² look-ups only when
    /// asked for.
    #[inline]
    fn evaluate_with(&self, g: Gaps, contact: bool, voltage: bool) -> HotForces {
        if let Some([s, v, c, _]) = self.fused_eval(g.bulge) {
            let e = |(value, d_bulge): (f64, f64)| ForceEval {
                value,
                d_bulge,
                d_pad: 0.0,
            };
            return HotForces {
                static_part: e(s),
                per_volt2: e(v),
                contact: non_negative(e(c)),
            };
        }
        HotForces {
            static_part: self.static_part(g),
            per_volt2: if voltage {
                self.per_volt2_part(g)
            } else {
                ForceEval::default()
            },
            contact: if contact {
                self.contact(g)
            } else {
                ForceEval::default()
            },
        }
    }

    /// Bounds of the interface force at `V² = volt2` (as `SliderModel::interface_force` sums it
    /// from [`InterfaceForces::coupled_sums`]), of its slope and of the contact force at every
    /// bulge gap in `[a, b]`; `None` where some term sees the pad gap, a point lies outside the
    /// tables (the exact fallback is not bounded) or a bound is not finite.
    pub(crate) fn bulge_bounds(&self, a: f64, b: f64, volt2: f64) -> Option<BulgeBounds> {
        if self.uses_pad_gap() {
            return None;
        }
        let zero = (Span::point(0.0), Span::point(0.0));
        let slot = |s: &PerGap| s[0].as_ref().map_or(Some(zero), |t| t.bounds(a, b));
        let (stat, per_v2) = match self.fused_bounds(a, b) {
            Some(bounds) => {
                let [s, v] = bounds?;
                (s, v)
            }
            None if volt2 != 0.0 => (slot(&self.static_part)?, slot(&self.per_volt2)?),
            None => (slot(&self.static_part)?, zero),
        };
        let (c, _) = slot(&self.contact)?;
        let out = BulgeBounds {
            force: stat.0.add(per_v2.0.scale(volt2)),
            slope: stat.1.add(per_v2.1.scale(volt2)),
            // A contact force is never negative (`non_negative`).
            contact: Span {
                lo: c.lo.max(0.0),
                hi: c.hi.max(0.0),
            },
        };
        [out.force, out.slope, out.contact]
            .iter()
            .all(|s| s.is_finite())
            .then_some(out)
    }

    /// Per gap (bulge, pad), a stretch `(from, to)` of gaps (m) over which every contact slope
    /// [`InterfaceForces::contact`] can return on that gap, as the tables give it, rounding
    /// included, is within `slope` (N/m) in magnitude: `to` is the tables' end, and `from` is
    /// found by bisection to within a millionth of the tables' range. `(−∞, ∞)` where no
    /// contact term sits on the gap (its slope is zero); an empty stretch (`from > to`) where
    /// even the tables' end is too steep. A clamped undershoot (`non_negative`) has zero slope,
    /// within any bound.
    pub(crate) fn contact_gentle(&self, slope: f64) -> [(f64, f64); 2] {
        let (lo, hi) = self.range;
        let steepest = |t: &Slot, a: f64| {
            t.bounds(a, hi)
                .map_or(f64::INFINITY, |(_, s)| s.lo.abs().max(s.hi.abs()))
        };
        self.contact.each_ref().map(|slot| {
            let Some(t) = slot else {
                return (f64::NEG_INFINITY, f64::INFINITY);
            };
            // A NaN bound compares false: not within, the safe side.
            let within = |a: f64| steepest(t, a) <= slope;
            if !within(hi) {
                return (f64::INFINITY, f64::NEG_INFINITY);
            }
            if within(lo) {
                return (lo, hi);
            }
            // `within(b)` holds and `within(a)` does not.
            let (mut a, mut b) = (lo, hi);
            while b - a > 1e-6 * (hi - lo) {
                let m = 0.5 * (a + b);
                if within(m) {
                    b = m;
                } else {
                    a = m;
                }
            }
            (b, hi)
        })
    }

    /// Real contact area, m², never negative: where the area is below the table's absolute
    /// tolerance an interpolation undershoot could make it slightly negative, and an area is not
    /// (the flash temperature takes its square root).
    #[inline]
    pub fn real_contact_area(&self, g: Gaps) -> f64 {
        let fused = if self.fused_area {
            self.fused_values(g.bulge)
        } else {
            None
        };
        match fused {
            Some([_, _, _, a]) => a,
            None => self.sum_value(&self.area, g),
        }
        .max(0.0)
    }

    /// [`InterfaceForces::real_contact_area`] and its slope along the bulge gap (m²/m), from the
    /// same table: the derivative of the interpolant that the value comes from.
    #[inline]
    pub(crate) fn real_contact_area_with_slope(&self, g: Gaps) -> (f64, f64) {
        let fused = if self.fused_area {
            self.fused_eval(g.bulge).map(|[_, _, _, a]| a)
        } else {
            None
        };
        let (a, slope) = fused.unwrap_or_else(|| {
            let e = self.sum(&self.area, g);
            (e.value, e.d_bulge)
        });
        // Clamped as the value alone is.
        if a > 0.0 {
            (a, slope)
        } else {
            (0.0, 0.0)
        }
    }

    /// The values alone of the interface force `F_static + V² G_e` at the squared voltage
    /// `volt2` (V²), of the contact force and of the real contact area: what a right-hand side
    /// needs, without the slopes. The same numbers as [`InterfaceForces::evaluate`] and
    /// [`InterfaceForces::real_contact_area`] give.
    ///
    /// ```no_run
    /// # fn main() -> hdi_tribology::Result<()> {
    /// use hdi_tribology::{force::Gaps, scene::Scene};
    /// let forces = Scene::paper().build_interface()?;
    /// let g = Gaps::same(2e-9);
    /// let v = forces.values(g, 0.25);
    /// let hot = forces.evaluate(g);
    /// assert_eq!(v.interface, hot.static_part.value + 0.25 * hot.per_volt2.value);
    /// assert_eq!(v.contact, hot.contact.value);
    /// assert_eq!(v.area, forces.real_contact_area(g));
    /// # Ok(()) }
    /// ```
    #[inline]
    pub fn values(&self, g: Gaps, volt2: f64) -> HotValues {
        if let Some([s, v, c, a]) = self.fused_values(g.bulge) {
            return HotValues {
                interface: by_coupling(s, v, volt2),
                contact: if c < 0.0 { 0.0 } else { c },
                area: if self.fused_area {
                    a.max(0.0)
                } else {
                    self.real_contact_area(g)
                },
            };
        }
        let per_volt2 = if volt2 != 0.0 {
            self.sum_value(&self.per_volt2, g)
        } else {
            0.0
        };
        let contact = self.sum_value(&self.contact, g);
        HotValues {
            interface: by_coupling(self.sum_value(&self.static_part, g), per_volt2, volt2),
            // Clamped as `contact` clamps it.
            contact: if contact < 0.0 { 0.0 } else { contact },
            area: self.real_contact_area(g),
        }
    }

    /// Every force by kind at the gaps `g` and squared voltage `volt2` (V²), through the tables.
    pub fn breakdown(&self, g: Gaps, volt2: f64) -> Breakdown {
        let mut b = Breakdown::default();
        for (kind, coupling, gap, t) in &self.by_kind {
            let d = match gap {
                GapReference::Bulge => g.bulge,
                GapReference::Pad => g.pad,
            };
            let v = t.eval(self.exact(), d).0;
            let x = match coupling {
                Coupling::Static => v,
                Coupling::PerVoltSquared => v * volt2,
            };
            match kind {
                TermKind::Intermolecular => b.intermolecular += x,
                TermKind::Contact => b.contact += x,
                TermKind::Electrostatic => {
                    if *coupling == Coupling::PerVoltSquared {
                        b.electrostatic_per_volt2 += v;
                    }
                    b.electrostatic += x;
                }
                TermKind::Other => b.other += x,
            }
        }
        // a contact force is never negative (see `InterfaceForces::contact`)
        b.contact = b.contact.max(0.0);
        b.real_contact_area = self.real_contact_area(g);
        b.total = b.intermolecular + b.contact + b.electrostatic + b.other;
        b
    }

    /// Every distinct table set, each once (a merged sum of one kind is that kind's table).
    fn distinct_tables(&self) -> Vec<&Arc<Tabulated>> {
        let mut out: Vec<&Arc<Tabulated>> = Vec::new();
        let slots = [
            &self.static_part,
            &self.per_volt2,
            &self.contact,
            &self.area,
        ];
        let all = self
            .by_kind
            .iter()
            .map(|(_, _, _, t)| t)
            .chain(slots.into_iter().flatten().flatten().map(|s| &s.tab));
        for t in all {
            if !out.iter().any(|o| Arc::ptr_eq(o, t)) {
                out.push(t);
            }
        }
        out
    }

    /// Appends the tables (not the terms) to a cache payload: every stored number as its bits, a
    /// table shared between sums once.
    pub(crate) fn encode_tables(&self, w: &mut Writer) {
        w.f64(self.range.0);
        w.f64(self.range.1);
        let tables = self.distinct_tables();
        let index = |t: &Arc<Tabulated>| tables.iter().position(|o| Arc::ptr_eq(o, t));
        w.usize(tables.len());
        for t in &tables {
            w.usize(t.members.len());
            for &m in &t.members {
                w.usize(m);
            }
            w.bool(t.area);
            w.f64s(&t.cuts);
            w.usize(t.segments.len());
            for s in &t.segments {
                s.encode(w);
            }
        }
        w.usize(self.by_kind.len());
        for (kind, coupling, gap, t) in &self.by_kind {
            w.u8(code(&KINDS, kind));
            w.u8(code(&COUPLINGS, coupling));
            w.u8(code(&GAPS, gap));
            w.usize(index(t).unwrap_or(0));
        }
        for slots in [
            &self.static_part,
            &self.per_volt2,
            &self.contact,
            &self.area,
        ] {
            for slot in slots {
                let i = slot.as_ref().and_then(|s| index(&s.tab));
                w.bool(i.is_some());
                w.usize(i.unwrap_or(0));
            }
        }
        w.bool(self.fused.is_some());
        if let Some(f) = &self.fused {
            f.encode(w);
        }
        w.bool(self.kinked.is_some());
        if let Some(k) = &self.kinked {
            k.encode(w);
        }
        w.bool(self.fused_area);
    }

    /// The forces of `terms` over `range` from tables written by
    /// [`InterfaceForces::encode_tables`] for the same terms and range: the same numbers, to the
    /// bit, as [`InterfaceForces::build`] gives. Every index read is checked.
    pub(crate) fn decode_tables(
        terms: Vec<Box<dyn InterfaceTerm>>,
        range: (f64, f64),
        r: &mut Reader<'_>,
    ) -> Result<Self> {
        let stored = (r.f64()?, r.f64()?);
        if stored.0.to_bits() != range.0.to_bits() || stored.1.to_bits() != range.1.to_bits() {
            return Err(malformed(format!(
                "tables over {stored:?}, wanted over {range:?}"
            )));
        }
        let count = r.count(1)?;
        let mut tables = Vec::with_capacity(count);
        for _ in 0..count {
            let n = r.count(8)?;
            let members = (0..n)
                .map(|_| r.index(terms.len()))
                .collect::<Result<Vec<_>>>()?;
            let area = r.bool()?;
            let cuts = r.finite_f64s()?;
            let n = r.count(1)?;
            if n != cuts.len() + 1 {
                return Err(malformed(format!(
                    "{n} table segments between {} cuts",
                    cuts.len()
                )));
            }
            let segments = (0..n)
                .map(|_| Table::decode(r))
                .collect::<Result<Vec<_>>>()?;
            tables.push(Arc::new(Tabulated {
                members,
                area,
                cuts,
                segments,
            }));
        }
        let n = r.count(4)?;
        let mut by_kind = Vec::with_capacity(n);
        for _ in 0..n {
            let kind = decode_code(&KINDS, r)?;
            let coupling = decode_code(&COUPLINGS, r)?;
            let gap = decode_code(&GAPS, r)?;
            by_kind.push((kind, coupling, gap, Arc::clone(&tables[r.index(count)?])));
        }
        let mut sums: [PerGap; 4] = Default::default();
        for slots in &mut sums {
            for slot in slots.iter_mut() {
                let present = r.bool()?;
                let i = r.usize()?;
                if present {
                    let t = tables
                        .get(i)
                        .ok_or_else(|| malformed(format!("index {i} of {count} table sets")))?;
                    *slot = Some(Slot::new(Arc::clone(t)));
                }
            }
        }
        let fused = if r.bool()? {
            Some(Arc::new(Fused::decode(r)?))
        } else {
            None
        };
        let kinked = if r.bool()? {
            Some(Arc::new(Fused::decode(r)?))
        } else {
            None
        };
        if fused.is_some() && kinked.is_some() {
            return Err(malformed(
                "both a smooth and a kinked fused table".to_string(),
            ));
        }
        let fused_area = r.bool()?;
        // Each table sums terms of the kind, coupling and gap it stands for.
        let fits = |t: &Tabulated, area: bool, f: &dyn Fn(&dyn InterfaceTerm) -> bool| {
            t.area == area && !t.members.is_empty() && t.members.iter().all(|&m| f(&*terms[m]))
        };
        let mut ok = by_kind.iter().all(|(k, c, g, t)| {
            fits(t, false, &|x| {
                x.kind() == *k && x.coupling() == *c && x.gap() == *g
            })
        });
        for (g, gap) in GAPS.into_iter().enumerate() {
            let [s, v, c, a] = sums.each_ref().map(|p| p[g].as_ref().map(|x| &*x.tab));
            ok &= s.is_none_or(|t| {
                fits(t, false, &|x| {
                    x.gap() == gap && x.coupling() == Coupling::Static
                })
            }) && v.is_none_or(|t| {
                fits(t, false, &|x| {
                    x.gap() == gap && x.coupling() == Coupling::PerVoltSquared
                })
            }) && c.is_none_or(|t| {
                fits(t, false, &|x| {
                    x.gap() == gap && x.kind() == TermKind::Contact
                })
            }) && a
                .is_none_or(|t| fits(t, true, &|x| x.gap() == gap && x.has_contact_area()));
        }
        if !ok {
            return Err(malformed("tables that do not fit the terms"));
        }
        let [static_part, per_volt2, contact, area] = sums;
        Ok(InterfaceForces {
            terms: Arc::new(terms),
            range,
            static_part,
            per_volt2,
            contact,
            area,
            by_kind,
            fused,
            kinked,
            fused_area,
            outside: OutsideTables::Exact,
        })
    }

    /// Whether any term depends on the voltage.
    pub fn has_voltage_terms(&self) -> bool {
        self.per_volt2.iter().any(Option::is_some)
    }

    /// Whether any contact term is enabled.
    pub fn has_contact(&self) -> bool {
        self.contact.iter().any(Option::is_some)
    }

    /// Whether any term sees the pad gap.
    pub fn uses_pad_gap(&self) -> bool {
        self.terms.iter().any(|t| t.gap() == GapReference::Pad)
    }

    /// The tabulated range of separations (m).
    pub fn table_range(&self) -> (f64, f64) {
        self.range
    }

    /// The same forces with `outside` as what they are outside the tables: the exact sum of the
    /// terms (the default) or NaN ([`OutsideTables`]). Inside the tables nothing changes; the
    /// tables are shared, not rebuilt.
    ///
    /// ```
    /// use hdi_tribology::force::{Gaps, OutsideTables};
    /// use hdi_tribology::scene::Scene;
    /// let exact = Scene::paper().build_interface()?;
    /// let refused = exact.clone().with_outside_tables(OutsideTables::Refused);
    /// let (inside, below) = (Gaps::same(1e-9), Gaps::same(exact.table_range().0 - 1e-9));
    /// assert_eq!(refused.values(inside, 0.25), exact.values(inside, 0.25));
    /// assert!(exact.contact(below).value > 0.0);
    /// assert!(refused.contact(below).value.is_nan());
    /// assert_eq!(refused.outside_tables(), OutsideTables::Refused);
    /// # Ok::<(), hdi_tribology::Error>(())
    /// ```
    pub fn with_outside_tables(self, outside: OutsideTables) -> Self {
        InterfaceForces { outside, ..self }
    }

    /// What the forces are outside the tables ([`InterfaceForces::with_outside_tables`]).
    pub fn outside_tables(&self) -> OutsideTables {
        self.outside
    }

    /// The terms a look-up outside the tables sums exactly, or `None` where it is refused.
    #[inline]
    fn exact(&self) -> Exact<'_> {
        match self.outside {
            OutsideTables::Exact => Some(&self.terms),
            OutsideTables::Refused => None,
        }
    }

    /// The terms, in the order given to [`InterfaceForces::build`].
    pub fn terms(&self) -> &[Box<dyn InterfaceTerm>] {
        &self.terms
    }

    /// Total number of table nodes (memory and build-cost indicator).
    pub fn table_nodes(&self) -> usize {
        let mut seen: Vec<*const Tabulated> = Vec::new();
        let all = self
            .static_part
            .iter()
            .chain(&self.per_volt2)
            .chain(&self.contact)
            .chain(&self.area)
            .flatten()
            .map(|s| &s.tab)
            .chain(self.by_kind.iter().map(|(_, _, _, t)| t));
        let mut n = 0;
        for t in all {
            let p = Arc::as_ptr(t);
            if !seen.contains(&p) {
                seen.push(p);
                n += t.segments.iter().map(Table::len).sum::<usize>();
            }
        }
        n + self.fused.as_ref().map_or(0, |f| f.len()) + self.kinked.as_ref().map_or(0, |k| k.len())
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scene::Scene;

    /// Every contact slope the look-up returns within a gentle stretch is within its bound,
    /// on whichever gap the contact term sits; the other gap's stretch is unbounded; and the
    /// stretch starts near where the slopes actually fall below the bound.
    #[test]
    fn a_gentle_stretch_holds_every_slope_within_its_bound() {
        for gap in [GapReference::Bulge, GapReference::Pad] {
            let mut scene = Scene::paper();
            scene.contact.as_mut().unwrap().gap = gap;
            let forces = scene.build_interface().unwrap();
            let (lo, hi) = forces.table_range();
            let k = usize::from(gap == GapReference::Pad);
            for bound in [1e1, 5e2, 1e4, 1e6] {
                let stretches = forces.contact_gentle(bound);
                assert_eq!(
                    stretches[1 - k],
                    (f64::NEG_INFINITY, f64::INFINITY),
                    "{gap:?}"
                );
                let (from, to) = stretches[k];
                assert_eq!(to, hi);
                assert!(from > lo && from < hi, "{gap:?} {bound}: {from:e}");
                let slope = |d: f64| {
                    let c = forces.contact(Gaps { bulge: d, pad: d });
                    c.d_bulge + c.d_pad
                };
                let n = 20_000;
                let mut steep_last = lo;
                for j in 0..=n {
                    let d = lo + (hi - lo) * j as f64 / n as f64;
                    let s = slope(d).abs();
                    if d >= from {
                        assert!(s <= bound, "{gap:?} {bound}: |F′({d:e})| = {s:e}");
                    }
                    if s > bound {
                        steep_last = d;
                    }
                }
                // Conservative, but not by more than a few table intervals' worth.
                assert!(
                    from - steep_last < 0.02e-9,
                    "{gap:?} {bound}: from {from:e}, last steep {steep_last:e}"
                );
            }
        }
    }
}
