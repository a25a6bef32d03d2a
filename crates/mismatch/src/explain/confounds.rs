//! Effects one recording cannot tell apart. Some effects of the vocabulary leave nearly the same
//! signature on a flight: a pure delay and a first-order motor lag (both a first-order lateness of
//! the commands); a wind through a drag, a thrust scale and a drag along the body axes (each can
//! be a steady force along the thrust); a wind and a tilted thrust axis (a steady sideways force,
//! as an uncalibrated attitude gives); a thrust scale and a ground effect at a nearly constant
//! height; a drag along the body axes and a rotor drag proportional to the thrust or to the rotor
//! speed (one force near hover), and those two rotor drags. The evidence rule tests each named effect against nothing; here each named effect that
//! has such stand-ins is tested against each of them:
//!
//! the effect is replaced by the stand-in, every other parameter refitted, and the stand-in
//! **explains as well** unless the named set is better by the evidence rule's own margins — the
//! fit-part likelihood ratio of the difference at least the χ² quantile of the rule's
//! significance (with as many degrees of freedom as the effect has parameters beyond the
//! stand-in's, at least 1), or the held-out residual at least `min_heldout_reduction` lower.
//!
//! - An effect that a stand-in explains **better** (the fit part better by the χ² margin, the
//!   held-out residual no higher), and a **wind** that a vehicle effect explains as well, are not
//!   named: the stand-in takes its place (and must then pass the evidence rule itself). A flight's
//!   air is the weaker explanation of a residual the vehicle's own physics explains.
//! - Any other effect that a stand-in explains as well stays in the fitted model (it explains the
//!   residual either way) but is reported as **not separable from this recording**, with the
//!   stand-ins and their fitted values, instead of being named.

use physics::{EffectId, EffectNumber, EffectParameters};
use serde::Serialize;

use crate::explain::evidence::{self, Baseline, EvidenceSettings, Judgement, chi_square_quantile};
use crate::explain::fit::FittedSet;
use crate::locate::problem::Problem;
use crate::model::refine::effects_from;

/// The stand-ins of an effect, in the order they are tried (each needs no other effect to act
/// through). Declared with the rule, before any evaluation data was seen, except the wind's thrust
/// tilt and the linear drag's rotor drags (docs/mismatch.md).
pub fn stand_ins(id: EffectId) -> &'static [EffectId] {
    use EffectId::*;
    match id {
        Delay => &[MotorLag],
        MotorLag => &[Delay],
        Wind => &[ThrustScale, LinearDrag, ThrustTilt],
        ThrustScale => &[LinearDrag, GroundEffect],
        LinearDrag => &[ThrustScale, RotorDrag, RotorSpeedDrag],
        RotorDrag => &[RotorSpeedDrag],
        RotorSpeedDrag => &[RotorDrag],
        GroundEffect => &[ThrustScale],
        _ => &[],
    }
}

/// One stand-in fitted in place of a named effect.
#[derive(Clone, Debug, Serialize)]
pub struct StandIn {
    pub id: EffectId,
    /// Its parameters fitted in the effect's place (fit part), with the others refitted.
    pub parameters: EffectParameters,
    /// How much worse the fit part is with the stand-in, `ΔSSE / (κ s²)` per channel group as in
    /// the evidence rule (negative: better), and the χ² quantile it is compared with.
    pub likelihood_ratio: f64,
    pub likelihood_ratio_threshold: f64,
    /// `1 − SSE(named) / SSE(stand-in)` on the held-out part (negative: the stand-in is better).
    pub heldout_increase: f64,
    /// Neither margin separates it from the named effect.
    pub explains_as_well: bool,
    /// It is better than the named effect by the fit-part margin (with a held-out residual no
    /// higher): the named effect is replaced by it.
    pub explains_better: bool,
}

/// A named effect that stand-ins were fitted in place of.
#[derive(Clone, Debug, Serialize)]
pub struct Confound {
    pub id: EffectId,
    pub stand_ins: Vec<StandIn>,
}

impl Confound {
    /// Whether some stand-in explains the recording as well.
    pub fn inseparable(&self) -> bool {
        self.stand_ins.iter().any(|s| s.explains_as_well)
    }
}

/// What the separation left: the judgement (re-judged when a stand-in replaced an effect), the
/// effects replaced by a stand-in, the effects not separable from a stand-in, and every test made.
#[derive(Clone, Debug)]
pub struct Separation {
    pub judgement: Judgement,
    /// Each effect a stand-in replaced: a wind one explains as well, or any effect one explains
    /// better.
    pub replaced: Vec<Confound>,
    pub not_separable: Vec<Confound>,
    /// Every named effect tested against its stand-ins, in order (the wind's first).
    pub tests: Vec<Confound>,
}

/// The settings of one separation: the evidence rule's, and the fit's.
pub struct Separate<'a> {
    pub settings: &'a EvidenceSettings,
    pub iterations: usize,
    pub block_rows: usize,
}

/// Tests every named effect of `judgement` against its stand-ins (see the module).
pub fn separate(problem: &Problem, judgement: Judgement, how: &Separate) -> Separation {
    let mut judgement = judgement;
    let mut replaced = Vec::new();
    let mut tests = Vec::new();
    // Each named effect with stand-ins, the wind first, is tested once; one a stand-in replaces
    // leaves a set judged anew.
    let mut order = judgement.set.ids();
    order.sort_by_key(|id| *id != EffectId::Wind);
    for id in order {
        if !judgement.set.ids().contains(&id) || stand_ins(id).is_empty() {
            continue;
        }
        let (confound, swapped) = weigh_against_stand_ins(problem, &judgement.set, id, how);
        let wins = |s: &StandIn| s.explains_better || (id == EffectId::Wind && s.explains_as_well);
        let best = confound
            .stand_ins
            .iter()
            .zip(swapped)
            .filter(|(s, _)| wins(s))
            .min_by(|a, b| a.0.likelihood_ratio.total_cmp(&b.0.likelihood_ratio));
        if let Some((_, swapped)) = best {
            // What the rule dropped before the replacement stays reported, first.
            let mut dropped = std::mem::take(&mut judgement.dropped);
            judgement = evidence::apply(
                problem,
                swapped,
                how.settings,
                how.iterations,
                how.block_rows,
            );
            dropped.append(&mut judgement.dropped);
            judgement.dropped = dropped;
            replaced.push(confound.clone());
        }
        if !confound.stand_ins.is_empty() {
            tests.push(confound);
        }
    }
    // What is left, tested against its stand-ins as the set now stands.
    let standing: Vec<Confound> = if replaced.is_empty() {
        tests.clone()
    } else {
        judgement
            .set
            .ids()
            .into_iter()
            .filter(|id| !stand_ins(*id).is_empty())
            .map(|id| weigh_against_stand_ins(problem, &judgement.set, id, how).0)
            .collect()
    };
    let not_separable = standing
        .into_iter()
        .filter(|c| c.id != EffectId::Wind && c.inseparable())
        .collect();
    Separation {
        judgement,
        replaced,
        not_separable,
        tests,
    }
}

/// Fits each stand-in of `id` that `set` does not already hold in `id`'s place and compares;
/// returns the comparison with each swapped set, in the same order.
fn weigh_against_stand_ins(
    problem: &Problem,
    set: &FittedSet,
    id: EffectId,
    how: &Separate,
) -> (Confound, Vec<FittedSet>) {
    let present = set.ids();
    let baseline = Baseline::of(problem, set, how.block_rows);
    let (stand_ins, swapped): (Vec<StandIn>, Vec<FittedSet>) = stand_ins(id)
        .iter()
        .filter(|a| !present.contains(a))
        .map(|&a| {
            let swapped = replace(problem, set, id, a, how);
            let extra = set
                .parameters
                .len()
                .saturating_sub(swapped.parameters.len());
            let worse = baseline.worse(problem, &swapped, &[id, a]);
            let fewer = swapped
                .parameters
                .len()
                .saturating_sub(set.parameters.len());
            let threshold = chi_square_quantile(extra.max(1), how.settings.significance);
            let better_threshold = chi_square_quantile(fewer.max(1), how.settings.significance);
            let stand_in = StandIn {
                id: a,
                parameters: swapped
                    .effects()
                    .parameters(a)
                    .expect("the stand-in is in the swapped set"),
                likelihood_ratio: worse.likelihood_ratio,
                likelihood_ratio_threshold: threshold,
                heldout_increase: worse.heldout_increase,
                explains_as_well: worse.likelihood_ratio < threshold
                    && worse.heldout_increase < how.settings.min_heldout_reduction,
                explains_better: -worse.likelihood_ratio >= better_threshold
                    && worse.heldout_increase <= 0.0,
            };
            (stand_in, swapped)
        })
        .unzip();
    (Confound { id, stand_ins }, swapped)
}

/// `set` with effect `id` replaced by `stand_in`, refitted: the stand-in started from the best
/// value of its profile grid (others held) when it has one number that is profiled, else
/// neutral.
fn replace(
    problem: &Problem,
    set: &FittedSet,
    id: EffectId,
    stand_in: EffectId,
    how: &Separate,
) -> FittedSet {
    let mut swapped = set.without(id);
    let numbers = EffectNumber::all_of(stand_in);
    let start: Vec<f64> = match numbers.as_slice() {
        [one] if !one.profile_grid().is_empty() => {
            vec![best_on_grid(problem, &swapped, *one)]
        }
        _ => numbers.iter().map(|n| n.neutral()).collect(),
    };
    swapped.parameters.extend(numbers);
    swapped.values.extend(start);
    swapped.refit(problem, how.iterations);
    swapped
}

/// The value of `number`'s profile grid (its neutral value left out) that best explains the fit
/// rows with `set`'s values held.
fn best_on_grid(problem: &Problem, set: &FittedSet, number: EffectNumber) -> f64 {
    let neutral = number.neutral();
    let grid: Vec<f64> = number
        .profile_grid()
        .into_iter()
        .filter(|v| *v != neutral)
        .collect();
    let sse = |value: f64| {
        let mut parameters = set.parameters.clone();
        let mut values = set.values.clone();
        parameters.push(number);
        values.push(value);
        let residual = problem.residual(&effects_from(&parameters, &values));
        problem.whitened_sse(&residual, 0..problem.split)
    };
    grid.into_iter()
        .map(|v| (v, sse(v)))
        .min_by(|a, b| a.1.total_cmp(&b.1))
        .map_or(neutral, |(v, _)| v)
}
