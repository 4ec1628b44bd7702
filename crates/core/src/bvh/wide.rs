//! A binary BVH collapsed into the compressed wide BVH8 (Ylitie, Karras and Laine 2017, §4), on
//! every core: the same tree as obvhs' `bvh2_to_cwbvh`, node for node and bit for bit (the tests
//! compare the two), which runs on one thread and took 60% of building the 871k-triangle dragon's
//! tree (docs/performance-log.md, session 29).
//!
//! Two passes, as obvhs': a bottom-up dynamic programme over the binary nodes chooses, for each node
//! and each number i + 1 ≤ 7 of wide slots it may fill, whether it becomes a leaf, an inner wide
//! node, or distributes the slots over its two children (surface-area costs); then a top-down pass
//! writes each wide node with its children quantised to its grid and ordered by ray octant. The
//! first runs independent subtrees on rayon's threads; the second converts the subtrees below the
//! top levels into their own lists and splices them in the order one thread would have appended
//! them. The costs go up the recursion rather than into a table: a binary node keeps only its
//! seven decisions, a byte each (obvhs keeps 56 bytes a node; 97 MB of the dragon's build).
//!
//! `collapse_over` joins wide trees built apart (a large mesh's runs, `chunked.rs`) under the wide
//! tree collapsed from a binary tree over their roots, each root kept whole as one inner child.

use std::sync::Mutex;
use std::sync::atomic::{AtomicU64, Ordering};

use glam::{Vec3A, vec3a};
use obvhs::bvh2::Bvh2;
use obvhs::cwbvh::node::CwBvhNode;
use rayon::prelude::*;

/// A leaf triangle's cost relative to a node's (obvhs' `PRIM_COST`).
const PRIM_COST: f32 = 0.3;
/// One over the quantisation grid's steps (obvhs' `DENOM`, 1/255).
const DENOM: f32 = 1.0 / 255.0;
/// Decision slots per binary node: how it fills 1..=7 wide slots.
const SLOTS: usize = 7;
/// No child chosen (obvhs' `INVALID`).
const NONE: u8 = u8::MAX;
/// Binary levels from the root above which the cost pass forks (2^levels tasks at most).
const PARALLEL_COST_LEVELS: u32 = 10;
/// A wide node's children lie at most seven binary levels below it (each level down spends a
/// slot) and a leaf of three primitives spans two more: a binary tree deeper than this collapses
/// into a wide one deeper than the kernel's stack, so the passes (recursive) stop there.
const MAX_BINARY_LEVELS: u32 = 7 * crate::bvh::MAX_WIDE_BVH_DEPTH as u32 + 2;
/// Wide levels from the root above which the conversion forks.
const PARALLEL_WIDE_LEVELS: u32 = 3;

#[derive(Clone, Copy, PartialEq, Eq, Debug)]
enum Kind {
    Leaf,
    Inner,
    Distribute,
}

/// One decision: for an inner node or a distribution, how many slots each child takes (`left` +
/// `right` + 2 = the slots; `NONE` where no split was found). Its cost is needed only while the
/// parent's decisions are made, so the cost pass hands costs up the recursion and keeps only
/// these, a byte each (seven per binary node: 7 bytes where obvhs keeps 56).
#[derive(Clone, Copy)]
struct Decision {
    kind: Kind,
    left: u8,
    right: u8,
}

impl Decision {
    fn pack(self) -> u8 {
        let kind = match self.kind {
            Kind::Leaf => 0,
            Kind::Inner => 1,
            Kind::Distribute => 2,
        };
        kind | self.left.min(7) << 2 | self.right.min(7) << 5
    }

    fn unpack(bits: u8) -> Self {
        let count = |c: u8| if c == 7 { NONE } else { c };
        Decision {
            kind: match bits & 3 {
                0 => Kind::Leaf,
                1 => Kind::Inner,
                _ => Kind::Distribute,
            },
            left: count((bits >> 2) & 7),
            right: count(bits >> 5),
        }
    }
}

/// The wide tree collapsed from `bvh2` (whose leaves must hold one primitive each, as PLOC's do):
/// its nodes, root first, and the primitive order its leaves index. `max_prims_per_leaf` is 1..=3.
pub fn bvh2_to_cwbvh(
    bvh2: &Bvh2,
    max_prims_per_leaf: u32,
) -> Result<(Vec<CwBvhNode>, Vec<u32>), String> {
    collapse(bvh2, max_prims_per_leaf).map(|(wide, _)| (wide.nodes, wide.primitives))
}

/// [`bvh2_to_cwbvh`] as lists, with the surface-area cost of its root as one wide child (what a
/// tree that takes it whole as a subtree weighs it by: [`collapse_over`]).
pub fn collapse(bvh2: &Bvh2, max_prims_per_leaf: u32) -> Result<(Wide, f32), String> {
    if bvh2.nodes.is_empty() {
        let empty = Wide {
            nodes: vec![CwBvhNode::default()],
            primitives: Vec::new(),
        };
        return Ok((empty, 0.0));
    }
    collapse_with(bvh2, max_prims_per_leaf, None)
}

/// The wide tree over wide trees built apart: `top`'s leaf holding primitive i stands for
/// `subtrees[i]` (its lists and its root's cost), which becomes one inner child, root node and
/// all, with its indices moved to where it lands. A subtree's root is never spread into its
/// parent's slots, the one way this tree differs from collapsing the whole binary tree at once.
pub fn collapse_over(top: &Bvh2, subtrees: Vec<(Wide, f32)>) -> Result<Wide, String> {
    let subtrees = Subtrees {
        costs: subtrees.iter().map(|(_, cost)| *cost).collect(),
        trees: subtrees
            .into_iter()
            .map(|(tree, _)| Mutex::new(Some(tree)))
            .collect(),
    };
    let (wide, _) = collapse_with(top, 3, Some(&subtrees))?;
    if subtrees
        .trees
        .iter()
        .any(|t| t.lock().is_ok_and(|t| t.is_some()))
    {
        return Err("a subtree was not placed in the wide tree over them".into());
    }
    Ok(wide)
}

fn collapse_with(
    bvh2: &Bvh2,
    max_prims_per_leaf: u32,
    subtrees: Option<&Subtrees>,
) -> Result<(Wide, f32), String> {
    if let Some(leaf) = bvh2.nodes.iter().find(|n| n.prim_count > 1) {
        return Err(format!(
            "the binary BVH has a leaf of {} primitives; the wide BVH is collapsed from leaves of one",
            leaf.prim_count
        ));
    }
    let collapse = Collapse {
        bvh2,
        decisions: (0..bvh2.nodes.len())
            .into_par_iter()
            .map(|_| AtomicU64::new(0))
            .collect(),
        subtrees,
    };
    let (_, costs) = collapse
        .cost(0, max_prims_per_leaf.clamp(1, 3), 0)
        .ok_or_else(|| {
            format!(
                "the binary BVH is deeper than {MAX_BINARY_LEVELS} levels, so its wide BVH \
                 would be deeper than the kernel's stack"
            )
        })?;
    let mut out = Wide {
        nodes: vec![CwBvhNode::default()],
        primitives: Vec::with_capacity(bvh2.primitive_indices.len()),
    };
    collapse.convert(0, 0, &mut out, 0);
    Ok((out, costs[0]))
}

struct Collapse<'a> {
    bvh2: &'a Bvh2,
    /// Each binary node's `SLOTS` decisions, a byte each (written once, by the cost pass's task
    /// for that node).
    decisions: Vec<AtomicU64>,
    /// Wide trees the binary tree's leaves stand for, where it is a tree over them.
    subtrees: Option<&'a Subtrees>,
}

/// Wide trees built apart, taken once each as the conversion reaches their leaves.
struct Subtrees {
    trees: Vec<Mutex<Option<Wide>>>,
    costs: Vec<f32>,
}

/// Wide nodes and primitive indices written so far (a whole tree, or a subtree's own lists).
pub struct Wide {
    pub nodes: Vec<CwBvhNode>,
    pub primitives: Vec<u32>,
}

impl Wide {
    /// Puts `subtree` into these lists: its root node into `slot`, the rest appended, their child
    /// and primitive indices moved by where they land.
    fn splice(&mut self, slot: usize, subtree: Wide) {
        let node_shift = self.nodes.len() as u32 - 1;
        let primitive_shift = self.primitives.len() as u32;
        let mut nodes = subtree.nodes.into_iter().map(|mut n| {
            n.child_base_idx += node_shift;
            n.primitive_base_idx += primitive_shift;
            n
        });
        self.nodes[slot] = nodes.next().expect("a subtree has its node");
        self.nodes.extend(nodes);
        self.primitives.extend(subtree.primitives);
    }
}

impl Collapse<'_> {
    /// Which subtree `node` stands for, if it is a leaf of a tree over subtrees.
    fn subtree_at(&self, node: usize) -> Option<usize> {
        let n = &self.bvh2.nodes[node];
        (self.subtrees.is_some() && n.prim_count != 0)
            .then(|| self.bvh2.primitive_indices[n.first_index as usize] as usize)
    }

    fn decision(&self, node: usize, slot: usize) -> Decision {
        let bits = self.decisions[node].load(Ordering::Relaxed);
        Decision::unpack((bits >> (8 * slot)) as u8)
    }

    fn set(&self, node: usize, decisions: [Decision; SLOTS]) {
        let bits = decisions.iter().enumerate().fold(0u64, |bits, (slot, d)| {
            bits | u64::from(d.pack()) << (8 * slot)
        });
        self.decisions[node].store(bits, Ordering::Relaxed);
    }

    /// Makes the decisions of `node`'s subtree (children first); returns its primitive count and
    /// the cost of each of its decisions, or `None` where the tree is deeper than
    /// `MAX_BINARY_LEVELS`.
    fn cost(
        &self,
        node: usize,
        max_prims_per_leaf: u32,
        level: u32,
    ) -> Option<(u32, [f32; SLOTS])> {
        if level > MAX_BINARY_LEVELS {
            return None;
        }
        let n = &self.bvh2.nodes[node];
        let half_area = n.aabb().half_area();
        if let Some(subtree) = self.subtree_at(node) {
            // One inner child, whatever the slots; too many primitives for any leaf above it.
            let inner = Decision {
                kind: Kind::Inner,
                left: NONE,
                right: NONE,
            };
            self.set(node, [inner; SLOTS]);
            let cost = self.subtrees.map_or(0.0, |s| s.costs[subtree]);
            return Some((u32::MAX / 2, [cost; SLOTS]));
        }
        if n.prim_count != 0 {
            let leaf = Decision {
                kind: Kind::Leaf,
                left: 0,
                right: 0,
            };
            self.set(node, [leaf; SLOTS]);
            let cost = half_area * (n.prim_count as f32) * PRIM_COST;
            return Some((n.prim_count, [cost; SLOTS]));
        }
        let (left, right) = (n.first_index as usize, n.first_index as usize + 1);
        let ((left_primitives, left_costs), (right_primitives, right_costs)) =
            if level < PARALLEL_COST_LEVELS {
                let (a, b) = rayon::join(
                    || self.cost(left, max_prims_per_leaf, level + 1),
                    || self.cost(right, max_prims_per_leaf, level + 1),
                );
                (a?, b?)
            } else {
                (
                    self.cost(left, max_prims_per_leaf, level + 1)?,
                    self.cost(right, max_prims_per_leaf, level + 1)?,
                )
            };
        let primitives = left_primitives.saturating_add(right_primitives);
        let pair = |k: usize, j: usize| left_costs[k] + right_costs[j];
        // One slot: a leaf if few enough primitives, else an inner node over the best split of
        // seven slots between the children.
        let leaf_cost = if primitives <= max_prims_per_leaf {
            (primitives as f32) * half_area * PRIM_COST
        } else {
            f32::INFINITY
        };
        let (mut best, mut split) = (f32::INFINITY, (NONE, NONE));
        for k in 0..SLOTS {
            let c = pair(k, SLOTS - 1 - k);
            if c < best {
                (best, split) = (c, (k as u8, (SLOTS - 1 - k) as u8));
            }
        }
        let inner_cost = best + half_area;
        let (cost, kind) = if leaf_cost < inner_cost {
            (leaf_cost, Kind::Leaf)
        } else {
            (inner_cost, Kind::Inner)
        };
        let mut decisions = [Decision {
            kind,
            left: split.0,
            right: split.1,
        }; SLOTS];
        let mut costs = [cost; SLOTS];
        // i + 1 slots: as many as i, or split between the children.
        for i in 1..SLOTS {
            let (mut best, mut split) = (costs[i - 1], (NONE, NONE));
            for k in 0..i {
                let c = pair(k, i - k - 1);
                if c < best {
                    (best, split) = (c, (k as u8, (i - k - 1) as u8));
                }
            }
            (decisions[i], costs[i]) = if split.0 != NONE {
                let split = Decision {
                    kind: Kind::Distribute,
                    left: split.0,
                    right: split.1,
                };
                (split, best)
            } else {
                (decisions[i - 1], costs[i - 1])
            };
        }
        self.set(node, decisions);
        Some((primitives, costs))
    }

    /// Writes the wide node at `out.nodes[slot]` for binary node `node` and, below it, its
    /// subtree (appended to `out`, as obvhs appends it).
    fn convert(&self, slot: usize, node: usize, out: &mut Wide, level: u32) {
        if let Some(subtree) = self.subtree_at(node) {
            let taken = self
                .subtrees
                .and_then(|s| s.trees[subtree].lock().ok()?.take());
            out.splice(slot, taken.expect("each subtree's leaf is reached once"));
            return;
        }
        let aabb = self.bvh2.nodes[node].aabb();
        let p = aabb.min;
        let mut wide = CwBvhNode {
            p: p.into(),
            ..Default::default()
        };
        let e = ((aabb.max - aabb.min).max(Vec3A::splat(1e-20)) * DENOM)
            .log2()
            .ceil()
            .exp2();
        let rcp_e = 1.0 / e;
        let exponent = |c: f32| (c.to_bits() >> 23) as u8;
        wide.e = [exponent(e.x), exponent(e.y), exponent(e.z)];

        let mut children = [u32::MAX; 8];
        let mut count = 0;
        self.children(node, &mut children, &mut count, 0);
        self.order_children(node, &mut children, count);

        wide.primitive_base_idx = out.primitives.len() as u32;
        wide.child_base_idx = out.nodes.len() as u32;
        let mut inner = Vec::with_capacity(8);
        let mut primitives = 0u32;
        for (i, &child) in children.iter().enumerate() {
            if child == u32::MAX {
                continue;
            }
            let child_aabb = self.bvh2.nodes[child as usize].aabb();
            let lo = ((child_aabb.min - p - 0.0) * rcp_e).floor();
            let hi = ((child_aabb.max - p + 0.0) * rcp_e).ceil();
            let lo = lo.clamp(Vec3A::ZERO, Vec3A::splat(255.0));
            let hi = hi.clamp(Vec3A::ZERO, Vec3A::splat(255.0));
            (
                wide.child_min_x[i],
                wide.child_min_y[i],
                wide.child_min_z[i],
            ) = (lo.x as u8, lo.y as u8, lo.z as u8);
            (
                wide.child_max_x[i],
                wide.child_max_y[i],
                wide.child_max_z[i],
            ) = (hi.x as u8, hi.y as u8, hi.z as u8);
            if self.decision(child as usize, 0).kind == Kind::Leaf {
                let count = self.push_primitives(child as usize, &mut out.primitives);
                // The three high bits are the primitive count in unary.
                wide.child_meta[i] =
                    primitives as u8 | [0, 0b0010_0000, 0b0110_0000, 0b1110_0000][count as usize];
                primitives += count;
            } else {
                wide.imask |= 1 << i;
                wide.child_meta[i] = (24 + i as u8) | 0b0010_0000;
                inner.push(child as usize);
            }
        }
        let first = out.nodes.len();
        out.nodes.resize(first + inner.len(), CwBvhNode::default());
        out.nodes[slot] = wide;
        if level < PARALLEL_WIDE_LEVELS && inner.len() > 1 {
            // Each inner child's subtree into lists of its own (its node first), then spliced in
            // order: its node into its slot, the rest appended with indices moved by where they
            // land.
            let subtrees: Vec<Wide> = inner
                .par_iter()
                .map(|&child| {
                    let mut own = Wide {
                        nodes: vec![CwBvhNode::default()],
                        primitives: Vec::new(),
                    };
                    self.convert(0, child, &mut own, level + 1);
                    own
                })
                .collect();
            for (offset, subtree) in subtrees.into_iter().enumerate() {
                out.splice(first + offset, subtree);
            }
        } else {
            for (offset, &child) in inner.iter().enumerate() {
                self.convert(first + offset, child, out, level + 1);
            }
        }
    }

    /// The binary nodes that `node`'s decision for `slot` + 1 slots makes its wide children.
    fn children(&self, node: usize, children: &mut [u32; 8], count: &mut usize, slot: usize) {
        let n = &self.bvh2.nodes[node];
        if n.prim_count != 0 {
            children[*count] = node as u32;
            *count += 1;
            return;
        }
        let decision = self.decision(node, slot);
        for (child, slots) in [
            (n.first_index as usize, decision.left),
            (n.first_index as usize + 1, decision.right),
        ] {
            if self.decision(child, slots as usize).kind == Kind::Distribute {
                self.children(child, children, count, slots as usize);
            } else {
                children[*count] = child as u32;
                *count += 1;
            }
        }
    }

    /// Places the children in the slots whose octant direction points most along them from the
    /// node's centre (greedy assignment, as obvhs; the paper's auction is barely better).
    fn order_children(&self, node: usize, children: &mut [u32; 8], count: usize) {
        let centre = self.bvh2.nodes[node].aabb().center();
        let direction = |s: usize| {
            let sign = |bit: usize| if s & bit != 0 { -1.0 } else { 1.0 };
            vec3a(sign(0b100), sign(0b010), sign(0b001))
        };
        let mut cost = [[f32::MAX; 8]; 8];
        for (s, d) in (0..8).map(|s| (s, direction(s))) {
            for c in 0..count {
                let v = self.bvh2.nodes[children[c] as usize].aabb().center() - centre;
                cost[c][s] = d.dot(v);
            }
        }
        let mut assignment = [usize::MAX; 8];
        let mut filled = [false; 8];
        loop {
            let (mut least, mut best) = (f32::MAX, None);
            for c in (0..count).filter(|&c| assignment[c] == usize::MAX) {
                for s in (0..8).filter(|&s| !filled[s]) {
                    if cost[c][s] < least {
                        (least, best) = (cost[c][s], Some((c, s)));
                    }
                }
            }
            let Some((c, s)) = best else { break };
            filled[s] = true;
            assignment[c] = s;
        }
        let original = std::mem::replace(children, [u32::MAX; 8]);
        for c in 0..count {
            children[assignment[c]] = original[c];
        }
    }

    /// Appends the primitives of `node`'s subtree in leaf order; returns how many.
    fn push_primitives(&self, node: usize, primitives: &mut Vec<u32>) -> u32 {
        let n = &self.bvh2.nodes[node];
        if n.prim_count != 0 {
            primitives.push(self.bvh2.primitive_indices[n.first_index as usize]);
            return n.prim_count;
        }
        self.push_primitives(n.first_index as usize, primitives)
            + self.push_primitives(n.first_index as usize + 1, primitives)
    }
}

#[cfg(test)]
mod tests;
