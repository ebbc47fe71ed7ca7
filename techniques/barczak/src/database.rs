//! The visibility database for moving objects (Barczak 2006 §4.5.1–4.5.2, Table 4-1).
//!
//! Reads: the lights, the receivers (patch trees and complex objects' bounding spheres) and the
//! blockers, each tagged with its object; a mover's rigid motion.
//! Writes: per receiver node and light, the blockers reaching into the node's occlusion pyramid
//! (each partial or full) and the light's [`LightState`] inferred from them; per motion, the
//! light-map changes (a leaf gaining or losing a light: fully blocked or behind ⇄ lit) and the
//! shadow maps the motion affects.
//!
//! What is stored follows one rule per blocker and node: at a root the blocker is tested; below,
//! a blocker *full* on the parent is full on the child (no test), one *partial* on the parent is
//! tested on the child, one missing the parent is missing on the child (the child's pyramid lies
//! inside the parent's). A node behind the light stores nothing. So a blocker is stored in every
//! node its recursion reaches, "once as a partial occluder and once as a full occluder" where it
//! changes, as the thesis describes.
//!
//! When an object moves ([`VisibilityDatabase::move_object`]): its own receivers are recomputed;
//! for every other receiver and light only the mover's blockers are revisited, top down, with
//! Table 4-1's cases: unchanged full or unchanged missing ends the descent; partial (unchanged
//! or new) recurses with tests; a change to full or to missing is propagated to the children
//! without tests (the rule gives them full or missing). The result equals rebuilding the
//! database on the moved scene (tested).
//!
//! Only the movers' blockers need their lists afterwards (a motion revisits the mover's
//! blockers only), so [`VisibilityDatabase::build_keeping_movers`] folds every static blocker
//! into a per-entry summary, the strongest occlusion among them, as soon as a receiver is
//! computed: the states are the same (tested), and a scene of tens of thousands of charts keeps
//! a few bytes per node and light instead of every blocker reaching in.

use glam::Vec3;
use rayon::prelude::*;

use crate::blocker_index::{clusters, BlockerIndex};
use crate::visibility::{Blocker, LightState, Occlusion, PatchTree, PointLight, Reach};

/// A receiver's geometry.
#[derive(Clone, Debug)]
pub enum ReceiverShape {
    /// A planar patch and its sub-patches (light-mapped).
    Patch(PatchTree),
    /// A complex object's bounding sphere (lit by PRT; one node).
    Object { center: Vec3, radius: f32 },
}

/// A receiver: its object and geometry.
#[derive(Clone, Debug)]
pub struct Receiver {
    pub object: u32,
    pub shape: ReceiverShape,
}

impl Receiver {
    pub fn node_count(&self) -> usize {
        match &self.shape {
            ReceiverShape::Patch(t) => t.nodes.len(),
            ReceiverShape::Object { .. } => 1,
        }
    }
    fn children(&self, node: usize) -> Option<[u32; 4]> {
        match &self.shape {
            ReceiverShape::Patch(t) => t.nodes[node].children,
            ReceiverShape::Object { .. } => None,
        }
    }
    /// A sphere holding the receiver (centre, radius).
    fn bounds(&self) -> (Vec3, f32) {
        match &self.shape {
            ReceiverShape::Patch(t) => {
                let corners = t.nodes[0].corners;
                let centre = corners.iter().copied().sum::<Vec3>() / 4.0;
                let radius = corners.iter().map(|c| (*c - centre).length());
                (centre, radius.fold(0f32, f32::max))
            }
            ReceiverShape::Object { center, radius } => (*center, *radius),
        }
    }
    fn reach(&self, node: usize, light: &PointLight) -> Reach {
        match &self.shape {
            ReceiverShape::Patch(t) => {
                Reach::patch(light, t.nodes[node].corners, t.normal, t.tolerance(light))
            }
            ReceiverShape::Object { center, radius } => Reach::object(light, *center, *radius),
        }
    }
    /// Moves the receiver by the rigid map `to`.
    fn transform(&mut self, to: &impl Fn(Vec3) -> Vec3) {
        match &mut self.shape {
            ReceiverShape::Patch(t) => {
                let origin = t.nodes[0].corners[0];
                t.normal = (to(origin + t.normal) - to(origin)).normalize();
                for n in &mut t.nodes {
                    n.corners = n.corners.map(to);
                }
                for tri in &mut t.surface {
                    *tri = tri.map(to);
                }
            }
            ReceiverShape::Object { center, .. } => *center = to(*center),
        }
    }
}

/// What the database stores for one node and light.
#[derive(Clone, Debug, PartialEq, Default)]
pub struct NodeEntry {
    pub state: Option<LightState>,
    /// Blockers reaching in, by blocker index, ascending: every one, or after
    /// [`VisibilityDatabase::keep_movers_only`] only the movable objects'.
    pub blockers: Vec<(u32, Occlusion)>,
    /// The strongest occlusion among the blockers no longer listed (the static ones).
    pub fixed: Option<Occlusion>,
}

impl NodeEntry {
    /// The light's state over the node, from the blockers listed and the fixed ones.
    fn state_in(&self, reach: &Reach) -> LightState {
        match (reach.state(&self.blockers), self.fixed) {
            (LightState::Behind, _) => LightState::Behind,
            (_, Some(Occlusion::Full)) => LightState::Blocked,
            (LightState::Unblocked, Some(Occlusion::Partial)) => LightState::Partial,
            (state, _) => state,
        }
    }

    /// Folds the blockers whose objects are not `movable` into [`NodeEntry::fixed`].
    fn keep_only(&mut self, blockers: &[Blocker], movable: &[u32]) {
        let moves = |b: u32| movable.binary_search(&blockers[b as usize].object).is_ok();
        for &(b, o) in &self.blockers {
            if !moves(b) && self.fixed != Some(Occlusion::Full) {
                self.fixed = Some(o);
            }
        }
        self.blockers.retain(|&(b, _)| moves(b));
        self.blockers.shrink_to_fit();
    }
}

/// [`NodeEntry::keep_only`] on every entry of one receiver (`[node][light]`).
fn keep_only(entries: &mut [Vec<NodeEntry>], blockers: &[Blocker], movable: &[u32]) {
    for entry in entries.iter_mut().flatten() {
        entry.keep_only(blockers, movable);
    }
}

/// A light added to or removed from a leaf's light map.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct LightMapChange {
    pub receiver: u32,
    pub node: u32,
    pub light: u32,
    /// True: the light now lights the leaf (add its contribution); false: remove it.
    pub add: bool,
}

/// What one motion changed.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Update {
    pub light_map: Vec<LightMapChange>,
    /// Lights whose shadow maps see the mover before or after the motion, ascending.
    pub shadow_maps: Vec<u32>,
    /// Blocker-against-pyramid tests made.
    pub tests: usize,
}

/// See the module docs.
#[derive(Clone, Debug)]
pub struct VisibilityDatabase {
    pub lights: Vec<PointLight>,
    pub receivers: Vec<Receiver>,
    pub blockers: Vec<Blocker>,
    /// `[receiver][node][light]`.
    entries: Vec<Vec<Vec<NodeEntry>>>,
    /// The blockers' boxes, to test a root pyramid only against those that may reach in.
    index: BlockerIndex,
    /// After [`VisibilityDatabase::keep_movers_only`]: the objects that may move, ascending.
    movable: Option<Vec<u32>>,
}

/// Receivers whose searches of the blocker index are shared (see [`Shared::recompute`]).
const GROUP: usize = 8;

/// Whether a light lights a node in this state (it belongs in the light map).
fn lit(state: Option<LightState>) -> bool {
    matches!(state, Some(LightState::Unblocked | LightState::Partial))
}

/// A receiver being computed and its entries (`[node][light]`).
type Member<'a> = (&'a Receiver, &'a mut Vec<Vec<NodeEntry>>);

/// What every receiver's computation reads: the lights, the blockers and their index.
struct Shared<'a> {
    lights: &'a [PointLight],
    blockers: &'a [Blocker],
    index: &'a BlockerIndex,
}

impl Shared<'_> {
    /// Recomputes every node of the receivers of `group` (near one another; each with its
    /// `entries`, `[node][light]`) for every light against every blocker, those the index
    /// rules out for a root's reach left out (the exact test would reject them).
    ///
    /// Per light, one search of the index with a pyramid from the light around the whole
    /// group finds the blockers that may reach into any member's pyramid (each lies inside
    /// it); each member keeps those its own root's reach does not rule out: the blockers a
    /// search with its own reach would find, for one search per group instead of one per
    /// member. A light inside the group's sphere searches per member.
    fn recompute(&self, group: &mut [Member]) -> usize {
        let spheres: Vec<(Vec3, f32)> = group.iter().map(|(r, _)| r.bounds()).collect();
        let (lo, hi) = spheres.iter().fold(
            (Vec3::splat(f32::INFINITY), Vec3::splat(f32::NEG_INFINITY)),
            |(lo, hi), (c, r)| (lo.min(*c - *r), hi.max(*c + *r)),
        );
        let centre = (lo + hi) * 0.5;
        let radius = spheres
            .iter()
            .map(|(c, r)| (*c - centre).length() + r)
            .fold(0f32, f32::max);
        // Widened a little, so that rounding never leaves a member's point outside.
        let radius = radius * (1.0 + 1e-4);
        let (mut near, mut candidates) = (Vec::new(), Vec::new());
        let mut tests = 0;
        for (l, light) in self.lights.iter().enumerate() {
            let around = match group {
                [(only, _)] => only.reach(0, light),
                _ => Reach::around(light, centre, radius),
            };
            let shared = !matches!(around, Reach::Everything);
            if shared {
                (self.index).query(|lo, hi, mask| around.cull(lo, hi, mask), &mut near);
            }
            for (receiver, entries) in group.iter_mut() {
                let reach = receiver.reach(0, light);
                if shared {
                    candidates.clear();
                    candidates.extend(near.iter().copied().filter(|&b| {
                        let (lo, hi) = self.index.bounds_of(b);
                        !reach.rules_out(lo, hi)
                    }));
                } else {
                    (self.index).query(|lo, hi, mask| reach.cull(lo, hi, mask), &mut candidates);
                }
                for node in entries.iter_mut() {
                    node[l] = NodeEntry::default();
                }
                tests += self.visit(receiver, entries, l, 0, None, &candidates, true);
            }
        }
        tests
    }

    /// Brings node `n` of `receiver` (its `entries`) for light `l` up to date for the
    /// blockers `only` (ascending), given its parent's entry (`None` at the root), and descends
    /// where Table 4-1 says so; `full` recomputes the whole subtree (its entries were reset).
    /// Returns the tests made.
    #[allow(clippy::too_many_arguments)]
    fn visit(
        &self,
        receiver: &Receiver,
        entries: &mut [Vec<NodeEntry>],
        l: usize,
        n: usize,
        parent: Option<&NodeEntry>,
        only: &[u32],
        full: bool,
    ) -> usize {
        let reach = receiver.reach(n, &self.lights[l]);
        let revisited = |b: &u32| only.binary_search(b).is_ok();
        let mut tests = 0;
        let mut test = |b: u32| {
            tests += 1;
            reach.test(&self.blockers[b as usize].shape).map(|o| (b, o))
        };
        // Ascending by blocker, as `only` and the parent's list are.
        let fresh: Vec<(u32, Occlusion)> = match (&reach, parent) {
            (Reach::Behind, _) => Vec::new(),
            // At a root, a blocker whose box lies outside the reach cannot reach in (the exact
            // test would say so; in a recomputation the index already left such blockers out).
            (_, None) => (only.iter().copied())
                .filter(|&b| self.blockers[b as usize].object != receiver.object)
                .filter(|&b| {
                    let (lo, hi) = self.index.bounds_of(b);
                    full || !reach.rules_out(lo, hi)
                })
                .filter_map(&mut test)
                .collect(),
            // Below the root only the parent's blockers can reach in: full stays full, partial
            // is tested again, missing stays missing.
            (_, Some(p)) => (p.blockers.iter())
                .filter(|(b, _)| revisited(b))
                .filter_map(|&(b, o)| match o {
                    Occlusion::Full => Some((b, o)),
                    Occlusion::Partial => test(b),
                })
                .collect(),
        };
        let entry = &mut entries[n][l];
        // The entries of the blockers not revisited stay; the revisited ones are replaced. A
        // full recomputation (a moved or new receiver) also renews the state: its reach moved.
        let unchanged = !full
            && entry.state.is_some()
            && entry
                .blockers
                .iter()
                .filter(|(b, _)| revisited(b))
                .eq(fresh.iter());
        let descend = !unchanged || fresh.iter().any(|(_, o)| *o == Occlusion::Partial);
        if !unchanged {
            entry.blockers.retain(|(b, _)| !revisited(b));
            entry.blockers.extend(fresh);
            entry.blockers.sort_unstable_by_key(|(b, _)| *b);
            entry.state = Some(entry.state_in(&reach));
        }
        if descend {
            if let Some(children) = receiver.children(n) {
                // Children never read their parent's entry: lend it to them without a copy.
                let parent = std::mem::take(&mut entries[n][l]);
                for c in children {
                    tests +=
                        self.visit(receiver, entries, l, c as usize, Some(&parent), only, full);
                }
                entries[n][l] = parent;
            }
        }
        tests
    }
}

impl VisibilityDatabase {
    /// The database of the scene, computed in full. Returns it and the tests made.
    pub fn build(
        lights: Vec<PointLight>,
        receivers: Vec<Receiver>,
        blockers: Vec<Blocker>,
    ) -> (VisibilityDatabase, usize) {
        Self::build_with(lights, receivers, blockers, None)
    }

    /// [`VisibilityDatabase::build`] followed by [`VisibilityDatabase::keep_movers_only`], each
    /// receiver's lists folded as soon as they are computed (the full lists of every receiver
    /// are never held at once).
    pub fn build_keeping_movers(
        lights: Vec<PointLight>,
        receivers: Vec<Receiver>,
        blockers: Vec<Blocker>,
        movable: &[u32],
    ) -> (VisibilityDatabase, usize) {
        let mut movable = movable.to_vec();
        movable.sort_unstable();
        Self::build_with(lights, receivers, blockers, Some(movable))
    }

    fn build_with(
        lights: Vec<PointLight>,
        receivers: Vec<Receiver>,
        blockers: Vec<Blocker>,
        movable: Option<Vec<u32>>,
    ) -> (VisibilityDatabase, usize) {
        let mut db = VisibilityDatabase {
            entries: receivers
                .iter()
                .map(|r| vec![vec![NodeEntry::default(); lights.len()]; r.node_count()])
                .collect(),
            index: BlockerIndex::new(&blockers),
            lights,
            receivers,
            blockers,
            movable,
        };
        // Receivers are independent: computed in parallel, the same as one after another, in
        // groups of neighbours that share their searches of the index.
        let scene = Shared {
            lights: &db.lights,
            blockers: &db.blockers,
            index: &db.index,
        };
        let movable = db.movable.as_deref();
        // Patches only: a patch's pyramid is the hull of the light and the patch, inside the
        // group's. A complex object's is squared around its sphere's cone, and its corners may
        // stick out of the group's: each object is a group of its own.
        let patches: Vec<u32> = (0..db.receivers.len() as u32)
            .filter(|&r| matches!(db.receivers[r as usize].shape, ReceiverShape::Patch(_)))
            .collect();
        let centres: Vec<Vec3> = (patches.iter())
            .map(|&r| db.receivers[r as usize].bounds().0)
            .collect();
        let objects = (0..db.receivers.len() as u32)
            .filter(|r| patches.binary_search(r).is_err())
            .map(|r| vec![r]);
        let mut slots: Vec<Option<&mut Vec<Vec<NodeEntry>>>> =
            db.entries.iter_mut().map(Some).collect();
        let mut groups: Vec<Vec<Member>> = (clusters(&centres, GROUP).into_iter())
            .map(|g| g.into_iter().map(|i| patches[i as usize]).collect())
            .chain(objects)
            .map(|g: Vec<u32>| {
                g.into_iter()
                    .map(|r| {
                        let entries = slots[r as usize].take().expect("in one group");
                        (&db.receivers[r as usize], entries)
                    })
                    .collect()
            })
            .collect();
        let tests = (groups.par_iter_mut())
            .map(|group| {
                let tests = scene.recompute(group);
                if let Some(movable) = movable {
                    for (_, entries) in group.iter_mut() {
                        keep_only(entries, scene.blockers, movable);
                    }
                }
                tests
            })
            .sum();
        (db, tests)
    }

    /// Keeps in each entry's list only the blockers of the objects that may move (`movable`),
    /// the others folded into [`NodeEntry::fixed`]: static blockers never change, so only the
    /// movers' lists are read again ([`VisibilityDatabase::move_object`] revisits the mover's
    /// blockers only). The states are unchanged; memory falls to the movers' share (none on a
    /// scene without movers). Only the objects named here may move afterwards.
    pub fn keep_movers_only(&mut self, movable: &[u32]) {
        let mut movable = movable.to_vec();
        movable.sort_unstable();
        let blockers = &self.blockers;
        (self.entries.par_iter_mut()).for_each(|entries| keep_only(entries, blockers, &movable));
        self.movable = Some(movable);
    }

    /// The entry of `node` of `receiver` for `light`.
    pub fn entry(&self, receiver: usize, node: usize, light: usize) -> &NodeEntry {
        &self.entries[receiver][node][light]
    }

    /// The light's state over the node.
    pub fn state(&self, receiver: usize, node: usize, light: usize) -> LightState {
        self.entries[receiver][node][light]
            .state
            .expect("every node is computed")
    }

    /// Every entry, `[receiver][node][light]` (to compare two databases).
    pub fn entries(&self) -> &[Vec<Vec<NodeEntry>>] {
        &self.entries
    }

    /// Moves `object` (its blockers and receivers) by the rigid map `to` and updates the
    /// database (see the module docs).
    pub fn move_object(&mut self, object: u32, to: impl Fn(Vec3) -> Vec3) -> Update {
        if let Some(movable) = &self.movable {
            assert!(
                movable.binary_search(&object).is_ok(),
                "object {object} was not named movable when the database kept movers only"
            );
        }
        let leaf_states = |db: &VisibilityDatabase| -> Vec<(u32, u32, u32, bool)> {
            let mut v = Vec::new();
            for (r, rec) in db.receivers.iter().enumerate() {
                for n in 0..rec.node_count() {
                    if rec.children(n).is_none() {
                        for l in 0..db.lights.len() {
                            v.push((r as u32, n as u32, l as u32, lit(db.entries[r][n][l].state)));
                        }
                    }
                }
            }
            v
        };
        let sees_mover = |db: &VisibilityDatabase| -> Vec<bool> {
            (0..db.lights.len())
                .map(|l| {
                    db.receivers
                        .iter()
                        .enumerate()
                        .filter(|(_, r)| r.object == object)
                        .any(|(r, _)| lit(db.entries[r][0][l].state))
                })
                .collect()
        };
        let before = leaf_states(self);
        let seen_before = sees_mover(self);
        let moved: Vec<u32> = (0..self.blockers.len() as u32)
            .filter(|&b| self.blockers[b as usize].object == object)
            .collect();
        for &b in &moved {
            for p in self.blockers[b as usize].shape.points_mut() {
                *p = to(*p);
            }
            self.index.moved(b, &self.blockers);
        }
        for r in &mut self.receivers {
            if r.object == object {
                r.transform(&to);
            }
        }
        let scene = Shared {
            lights: &self.lights,
            blockers: &self.blockers,
            index: &self.index,
        };
        let mut tests = 0;
        for (receiver, entries) in self.receivers.iter().zip(&mut self.entries) {
            if receiver.object == object {
                // Moved: every node against every blocker (its reach moved).
                tests += scene.recompute(&mut [(receiver, entries)]);
                if let Some(movable) = &self.movable {
                    keep_only(entries, &self.blockers, movable);
                }
            } else {
                for l in 0..self.lights.len() {
                    tests += scene.visit(receiver, entries, l, 0, None, &moved, false);
                }
            }
        }
        let after = leaf_states(self);
        let seen_after = sees_mover(self);
        Update {
            light_map: before
                .iter()
                .zip(&after)
                .filter(|(a, b)| a.3 != b.3)
                .map(|(_, b)| LightMapChange {
                    receiver: b.0,
                    node: b.1,
                    light: b.2,
                    add: b.3,
                })
                .collect(),
            shadow_maps: (0..self.lights.len() as u32)
                .filter(|&l| seen_before[l as usize] || seen_after[l as usize])
                .collect(),
            tests,
        }
    }
}
