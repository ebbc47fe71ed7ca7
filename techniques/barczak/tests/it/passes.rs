//! The render-pass optimiser: it never adds passes, and every (object, light) pair stays in
//! exactly one element.

use std::collections::BTreeMap;

use gibench_barczak::passes::{one_per_object, optimise, total_passes, LightSet};

use gibench_harness::rng::SplitMix64 as Rng;

/// Objects whose partial lights cluster (neighbouring objects see overlapping ranges of
/// lights, as walls near the same blockers do), plus random strays.
fn instance(rng: &mut Rng, objects: usize, lights: u32) -> Vec<LightSet> {
    (0..objects)
        .map(|_| {
            let start = rng.below(lights as u64) as u32;
            let len = rng.below(lights as u64 / 2) as u32;
            let strays: Vec<u32> = (0..rng.below(10))
                .map(|_| rng.below(lights as u64) as u32)
                .collect();
            let set = LightSet::from_indices(
                (start..start + len)
                    .map(|l| l % lights)
                    .filter(|l| l % 3 != 0 || len.is_multiple_of(2))
                    .chain(strays),
            );
            if rng.below(8) == 0 {
                LightSet::default()
            } else {
                set
            }
        })
        .collect()
}

fn pairs(elements: &[gibench_barczak::passes::Element]) -> BTreeMap<(u32, u32), usize> {
    let mut m = BTreeMap::new();
    for e in elements {
        for &o in &e.objects {
            for l in e.lights.iter() {
                *m.entry((o, l)).or_insert(0) += 1;
            }
        }
    }
    m
}

#[test]
fn never_more_passes_and_every_pair_exactly_once() {
    let mut rng = Rng::from_state(3);
    let (mut before_all, mut after_all) = (0, 0);
    for case in 0..150 {
        let objects = 1 + rng.below(40) as usize;
        let k = 1 + rng.below(8) as usize;
        let lights = instance(&mut rng, objects, 300);
        let start = one_per_object(&lights);
        let before = total_passes(&start, k);
        let out = optimise(start.clone(), k);
        let after = total_passes(&out, k);
        assert!(after <= before, "case {case}: {before} -> {after} passes");
        let want = pairs(&start);
        let got = pairs(&out);
        assert!(
            got.values().all(|n| *n == 1),
            "case {case}: a pair is drawn twice"
        );
        assert_eq!(
            want.keys().collect::<Vec<_>>(),
            got.keys().collect::<Vec<_>>(),
            "case {case}"
        );
        assert!(out
            .iter()
            .all(|e| !e.lights.is_empty() && !e.objects.is_empty()));
        assert_eq!(out, optimise(start, k), "case {case}: not deterministic");
        before_all += before;
        after_all += after;
    }
    eprintln!("passes: {before_all} drawing each object alone, {after_all} optimised");
    assert!(
        after_all * 10 < before_all * 9,
        "the optimiser hardly merged: {before_all} -> {after_all}"
    );
}

/// The thesis' example (§4.3.5): 20 objects lit by the same 300 lights, 6 per pass, take 1000
/// passes alone and 50 together.
#[test]
fn twenty_objects_sharing_three_hundred_lights_take_fifty_passes() {
    let lights = vec![LightSet::from_indices(0..300); 20];
    let start = one_per_object(&lights);
    assert_eq!(total_passes(&start, 6), 1000);
    let out = optimise(start, 6);
    assert_eq!(total_passes(&out, 6), 50);
    assert_eq!(out.len(), 1);
    assert_eq!(out[0].objects, (0..20).collect::<Vec<u32>>());
}

/// Merges that save nothing are not made, counting the merged element's own passes: at K = 7
/// an object with 8 lights (2 passes) and one with 7 (1 pass) sharing one light would become
/// 1 + 1 + 1 passes; two with 7 sharing one, 1 + 1 + 1 instead of 2.
#[test]
fn merges_that_save_nothing_are_not_made() {
    for lights in [
        vec![LightSet::from_indices(0..8), LightSet::from_indices(7..14)],
        vec![LightSet::from_indices(0..7), LightSet::from_indices(6..13)],
    ] {
        let start = one_per_object(&lights);
        let out = optimise(start.clone(), 7);
        assert_eq!(out, start);
    }
}

/// Above `MAX_GREEDY` elements (a chart-patched scene): every (object, light) pair still drawn
/// exactly once, never more passes, deterministic, and objects with equal lights share an
/// element; in seconds, not the quadratic pass over all pairs.
#[test]
fn many_elements_keep_every_pair_once() {
    use gibench_barczak::passes::MAX_GREEDY;
    let mut rng = Rng::from_state(11);
    let objects = 3 * MAX_GREEDY + 17;
    let mut lights = instance(&mut rng, objects, 64);
    // Many objects with the same few light sets, as neighbouring charts have.
    for (i, l) in lights.iter_mut().enumerate().filter(|(i, _)| i % 3 == 0) {
        *l = LightSet::from_indices((i % 5) as u32..(i % 5) as u32 + 9);
    }
    let start = one_per_object(&lights);
    let k = 16;
    let out = optimise(start.clone(), k);
    assert!(total_passes(&out, k) <= total_passes(&start, k));
    let got = pairs(&out);
    assert!(got.values().all(|n| *n == 1), "a pair is drawn twice");
    assert_eq!(
        pairs(&start).keys().collect::<Vec<_>>(),
        got.keys().collect::<Vec<_>>()
    );
    for shift in 0..5u32 {
        let set = LightSet::from_indices(shift..shift + 9);
        let holders = out.iter().filter(|e| e.lights == set).count();
        assert!(
            holders <= 1,
            "lights {shift}..{}: {holders} elements",
            shift + 9
        );
    }
    assert_eq!(out, optimise(start, k), "not deterministic");
}
