//! Render-pass optimisation (Barczak 2006 §4.3.5, Figure 4-10).
//!
//! Reads: per object, the lights whose shadow maps it must read (its partially blocked ones
//! from [`crate::visibility`]), and K, the lights one pass handles (the thesis' X800 had
//! interpolators for 7; on wgpu a "pass" is a draw reading up to K shadow maps).
//! Writes: elements — sets of objects drawn together with the lights they share — such that
//! every (object, light) pair is in exactly one element, and the passes, Σ ⌈|lights| / K⌉, are
//! no more than drawing each object on its own.
//!
//! The greedy of Figure 4-10: start with one element per object; score every pair of elements
//! by the passes a merge saves; while some pair saves passes, merge the best pair (ties: the
//! lowest indices): the new element holds the union of their objects and the intersection of
//! their lights, which leave both parents; a parent left without lights is removed; pairs
//! with the new element are scored and pairs with a changed parent rescored. Each merge saves
//! at least one pass, so it ends.
//!
//! Scoring every pair needs memory and time in the square of the elements: fine for the
//! thesis' rooms (tens), not for a chart-patched scene (tens of thousands; on Sibenik one
//! plan did not finish in minutes). Above [`MAX_GREEDY`] elements, elements with equal
//! lights are joined first and the greedy runs on consecutive groups of [`MAX_GREEDY`]
//! (a deviation, in the README's table).

use std::cmp::Reverse;
use std::collections::BinaryHeap;

/// A set of light indices (a bit set).
#[derive(Clone, Debug, Default, PartialEq, Eq, Hash)]
pub struct LightSet {
    words: Vec<u64>,
}

impl LightSet {
    /// The set of `lights`.
    pub fn from_indices(lights: impl IntoIterator<Item = u32>) -> LightSet {
        let mut s = LightSet::default();
        for l in lights {
            let w = (l / 64) as usize;
            if s.words.len() <= w {
                s.words.resize(w + 1, 0);
            }
            s.words[w] |= 1 << (l % 64);
        }
        s
    }
    pub fn len(&self) -> usize {
        self.words.iter().map(|w| w.count_ones() as usize).sum()
    }
    pub fn is_empty(&self) -> bool {
        self.words.iter().all(|w| *w == 0)
    }
    /// The size of the intersection with `other` (without making it).
    pub fn shared(&self, other: &LightSet) -> usize {
        (self.words.iter().zip(&other.words))
            .map(|(a, b)| (a & b).count_ones() as usize)
            .sum()
    }
    pub fn intersection(&self, other: &LightSet) -> LightSet {
        let mut words: Vec<u64> = self
            .words
            .iter()
            .zip(&other.words)
            .map(|(a, b)| a & b)
            .collect();
        while words.last() == Some(&0) {
            words.pop();
        }
        LightSet { words }
    }
    pub fn difference(&self, other: &LightSet) -> LightSet {
        let mut words: Vec<u64> = self
            .words
            .iter()
            .enumerate()
            .map(|(i, a)| a & !other.words.get(i).copied().unwrap_or(0))
            .collect();
        while words.last() == Some(&0) {
            words.pop();
        }
        LightSet { words }
    }
    pub fn iter(&self) -> impl Iterator<Item = u32> + '_ {
        self.words.iter().enumerate().flat_map(|(i, w)| {
            (0..64)
                .filter(move |b| w >> b & 1 == 1)
                .map(move |b| (i * 64 + b) as u32)
        })
    }
}

/// Objects drawn together with the lights they share.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Element {
    /// Object indices, ascending.
    pub objects: Vec<u32>,
    pub lights: LightSet,
}

/// Passes to draw `lights` lights at `k` per pass.
pub fn passes(lights: usize, k: usize) -> usize {
    lights.div_ceil(k.max(1))
}

/// Passes the elements take at `k` lights per pass.
pub fn total_passes(elements: &[Element], k: usize) -> usize {
    elements.iter().map(|e| passes(e.lights.len(), k)).sum()
}

/// The passes merging `a` and `b` saves (negative: costs).
fn savings(a: &Element, b: &Element, k: usize) -> i64 {
    let ns = a.lights.shared(&b.lights);
    if ns == 0 {
        return 0;
    }
    let (na, nb) = (a.lights.len(), b.lights.len());
    (passes(na, k) + passes(nb, k)) as i64
        - (passes(na - ns, k) + passes(nb - ns, k) + passes(ns, k)) as i64
}

/// One element per object: object `i` with `lights[i]` (objects without lights are left out).
pub fn one_per_object(lights: &[LightSet]) -> Vec<Element> {
    lights
        .iter()
        .enumerate()
        .filter(|(_, l)| !l.is_empty())
        .map(|(i, l)| Element {
            objects: vec![i as u32],
            lights: l.clone(),
        })
        .collect()
}

/// Elements the greedy merges in one go at most: it scores every pair, so its memory and time
/// grow with the square of the count (the thesis' scenes had tens; a chart-patched scene has
/// tens of thousands).
pub const MAX_GREEDY: usize = 1024;

/// Figure 4-10's greedy merge of `elements` at `k` lights per pass (see the module docs);
/// returns the elements left, in creation order. Above [`MAX_GREEDY`] elements, elements
/// with equal lights are first joined into one (the merge that saves either of them the most:
/// all of one's passes) and the greedy then runs on consecutive groups of [`MAX_GREEDY`].
pub fn optimise(elements: Vec<Element>, k: usize) -> Vec<Element> {
    if elements.len() <= MAX_GREEDY {
        return greedy(elements, k);
    }
    let mut joined: Vec<Element> = Vec::new();
    let mut by_lights: std::collections::HashMap<LightSet, usize> =
        std::collections::HashMap::new();
    for e in elements {
        match by_lights.get(&e.lights) {
            Some(&i) => joined[i].objects.extend(e.objects),
            None => {
                by_lights.insert(e.lights.clone(), joined.len());
                joined.push(e);
            }
        }
    }
    for e in &mut joined {
        e.objects.sort_unstable();
    }
    let mut out = Vec::new();
    let mut rest = joined.into_iter();
    loop {
        let group: Vec<Element> = rest.by_ref().take(MAX_GREEDY).collect();
        if group.is_empty() {
            return out;
        }
        out.extend(greedy(group, k));
    }
}

/// Figure 4-10's greedy itself.
fn greedy(elements: Vec<Element>, k: usize) -> Vec<Element> {
    let mut live: Vec<Option<Element>> = elements.into_iter().map(Some).collect();
    let mut version: Vec<u32> = vec![0; live.len()];
    // (savings, lowest indices first, and the versions the score was taken at).
    type Entry = (i64, Reverse<usize>, Reverse<usize>, u32, u32);
    let mut heap: BinaryHeap<Entry> = BinaryHeap::new();
    let score = |live: &[Option<Element>],
                 version: &[u32],
                 heap: &mut BinaryHeap<Entry>,
                 i: usize,
                 j: usize| {
        let (Some(a), Some(b)) = (&live[i], &live[j]) else {
            return;
        };
        let s = savings(a, b, k);
        if s > 0 {
            let (i, j) = (i.min(j), i.max(j));
            heap.push((s, Reverse(i), Reverse(j), version[i], version[j]));
        }
    };
    for i in 0..live.len() {
        for j in i + 1..live.len() {
            score(&live, &version, &mut heap, i, j);
        }
    }
    while let Some((_, Reverse(i), Reverse(j), vi, vj)) = heap.pop() {
        if live[i].is_none() || live[j].is_none() || version[i] != vi || version[j] != vj {
            continue; // stale: one of the pair changed or went since it was scored
        }
        let (a, b) = (live[i].take().unwrap(), live[j].take().unwrap());
        let shared = a.lights.intersection(&b.lights);
        let mut objects: Vec<u32> = a.objects.iter().chain(&b.objects).copied().collect();
        objects.sort_unstable();
        objects.dedup();
        let merged = Element {
            objects,
            lights: shared.clone(),
        };
        let mut changed = Vec::new();
        for (idx, parent) in [(i, a), (j, b)] {
            let lights = parent.lights.difference(&shared);
            version[idx] += 1;
            if !lights.is_empty() {
                live[idx] = Some(Element {
                    objects: parent.objects,
                    lights,
                });
                changed.push(idx);
            }
        }
        live.push(Some(merged));
        version.push(0);
        changed.push(live.len() - 1);
        for &c in &changed {
            for other in 0..live.len() {
                if other != c && !(changed.contains(&other) && other < c) {
                    score(&live, &version, &mut heap, c, other);
                }
            }
        }
    }
    live.into_iter().flatten().collect()
}
