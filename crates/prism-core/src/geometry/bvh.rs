//! Our bounding volume hierarchy: eight children per node, whose boxes are tested against a
//! ray at once in SIMD, and leaves of up to four triangles intersected at once
//! ([`TrianglePack`]): the layout of Embree's `BVH8` with `Triangle4` leaves (Wald et al. 2014,
//! "Embree: A Kernel Framework for Efficient CPU Ray Tracing", §3–4).
//!
//! **Build.** A binary hierarchy is built by the `obvhs` crate: PLOC clustering of Morton-ordered
//! boxes (Meister & Bittner 2018) refined by reinsertion under the surface area heuristic
//! (Meister & Bittner 2017). It is then collapsed into the 8-wide tree that is cheapest by the
//! same heuristic, found by dynamic programming over the binary tree (Ylitie, Karras & Laine
//! 2017; see [`Plan`]): which binary subtrees become wide nodes, which become leaves (of at most
//! four triangles), and which spread their leaves into their parent's free children: fuller
//! nodes, and fewer leaves tested per ray, than opening the largest child until there are eight
//! (Wald, Benthin & Boulos 2008). Leaves are packed into [`TrianglePack`]s in depth-first order, small leaves sharing a pack
//! (each leaf knows its lanes) with one of the few packs opened last, so that packs are nearly
//! full and siblings lie together in memory. Analytic shapes (spheres, disks, moving shapes) are
//! leaves of their own. The subtrees under the root's children are collapsed in parallel.
//!
//! **Traversal.** Front to back, for closest hits and shadow rays alike: the children a ray
//! enters are visited nearest first and the others pushed on a stack with their entry
//! distance, which is skipped when popped beyond the nearest hit found so far; a shadow ray
//! stops at its first hit. The slab test is pbrt-v4's (§6.1.2): (bound − o)·(1/d) per axis,
//! the exit distance enlarged by 1 + 2γ(3) so that rounding never culls a box the ray touches
//! (pbrt-v4 §6.8.2), and zero direction components replaced by tiny ones so that no 0·∞ appears.
//! The eight boxes take one AVX instruction per step where the processor has AVX, else two SSE
//! or NEON instructions. AVX is detected at run time, so a binary built for any x86-64
//! (`RUSTFLAGS="-C target-cpu=x86-64"`) still uses it where it is present; the repository's own
//! build targets the processor that builds it (`.cargo/config.toml`), and runs there. Every
//! child about to be visited is prefetched whole, so that its cache lines arrive together:
//! on large scenes traversal waits mostly for memory. The triangle test of a leaf is inlined
//! into the traversal (so that it, too, runs in AVX's three-operand instructions) with the
//! ray's constants prepared once per ray ([`PackRay`]). Child boxes are f32 (not quantised).
//! docs/performance.md has the measurements behind these choices.
//!
//! **Refit.** When primitives move but stay the same primitives (a shape's transform changed),
//! [`Bvh::refit`] keeps the tree and recomputes its boxes (module `refit`), unless the tree got too
//! costly for the new places.

use std::mem::MaybeUninit;

use glam::Vec3;
use obvhs::aabb::Aabb;
use obvhs::bvh2::Bvh2;
use obvhs::bvh2::reinsertion::ReinsertionOptimizer;
use obvhs::ploc::{PlocBuilder, PlocSearchDistance, SortPrecision};
use rayon::prelude::*;
use std::sync::atomic::{AtomicU64, Ordering};
use wide::{CmpLe, f32x8};

use super::triangle::{TriangleHit, WatertightRay, gamma};
use super::triangle_pack::{PACK_WIDTH, PackRay, TrianglePack};
use crate::math::Ray;

mod refit;

pub use refit::{PrimitivePlaces, REFIT_COST_LIMIT};

/// A primitive to build the hierarchy over: a triangle, or an analytic shape given by its box.
#[derive(Clone, Copy, Debug)]
pub struct BuildPrimitive {
    /// The caller's number for the primitive, reported with its hits.
    pub id: u32,
    pub kind: PrimitiveKind,
}

#[derive(Clone, Copy, Debug)]
pub enum PrimitiveKind {
    Triangle([Vec3; 3]),
    /// Intersected by the caller (see [`Bvh::closest_hit`]); the box bounds it.
    Analytic {
        lo: Vec3,
        hi: Vec3,
    },
}

impl BuildPrimitive {
    fn aabb(&self) -> Aabb {
        let (lo, hi) = match self.kind {
            PrimitiveKind::Triangle([a, b, c]) => (a.min(b).min(c), a.max(b).max(c)),
            PrimitiveKind::Analytic { lo, hi } => (lo, hi),
        };
        Aabb::new(lo.into(), hi.into())
    }
}

/// A child of a node: an inner node, a leaf of triangles (a pack and its lanes), or an analytic
/// primitive. Bit 31 clear: inner node index. Bits 31 and 30 set: analytic primitive id in bits
/// 0–29. Bit 31 set and 30 clear: pack index in bits 0–25 and the leaf's lanes in bits 26–29.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
struct NodeRef(u32);

const LEAF: u32 = 1 << 31;
const ANALYTIC: u32 = 1 << 30;
const LANES_SHIFT: u32 = 26;
const PACK_INDEX_MASK: u32 = (1 << LANES_SHIFT) - 1;

impl NodeRef {
    fn inner(index: usize) -> NodeRef {
        assert!(index < LEAF as usize, "more BVH nodes than 2³¹");
        NodeRef(index as u32)
    }

    fn triangles(pack: usize, lanes: u32) -> NodeRef {
        assert!(
            pack <= PACK_INDEX_MASK as usize,
            "more than 2²⁶ triangle packs (2.7·10⁸ triangles) in one hierarchy"
        );
        NodeRef(LEAF | (lanes << LANES_SHIFT) | pack as u32)
    }

    fn analytic(id: u32) -> NodeRef {
        assert!(id < ANALYTIC, "analytic primitive id beyond 2³⁰");
        NodeRef(LEAF | ANALYTIC | id)
    }

    #[inline]
    fn is_inner(self) -> bool {
        self.0 & LEAF == 0
    }
}

/// The boxes of a node's [`NODE_WIDTH`] children, structure-of-arrays: `bounds[axis]` holds the
/// lower and `bounds[3 + axis]` the upper bounds. Empty slots have inverted bounds (+∞ below,
/// −∞ above), which no ray enters.
#[derive(Clone, Copy, Debug)]
#[repr(C, align(64))]
struct Node {
    bounds: [Lanes; 6],
    children: [NodeRef; NODE_WIDTH],
}

/// Children per node, and the SIMD type holding one coordinate of all their boxes.
const NODE_WIDTH: usize = 8;
type Lanes = f32x8;

/// Stack entries a query can hold without going to the heap; deeper trees use a heap stack.
/// The stack is not initialised (an entry is read only after it was pushed), which saves a
/// kilobyte of stores per ray.
const INLINE_STACK: usize = 128;

/// The hierarchy.
#[derive(Clone, Debug)]
pub struct Bvh {
    nodes: Vec<Node>,
    packs: Vec<TrianglePack>,
    root: NodeRef,
    lo: Vec3,
    hi: Vec3,
    /// Stack entries a query needs at most: NODE_WIDTH − 1 per level below the root, and one.
    stack_size: usize,
    /// Whether the processor has AVX, so that queries test eight boxes per instruction.
    avx: bool,
    /// The tree's cost by the surface area heuristic when it was built (see [`Bvh::refit`]).
    built_cost: f64,
}

/// A ray prepared for the slab tests: origin, reciprocal direction, and which bound of each
/// axis is entered first.
struct SlabRay {
    origin: [f32; 3],
    inv_dir: [f32; 3],
    /// Index into [`Node::bounds`] of the near and far bound per axis.
    near: [usize; 3],
    far: [usize; 3],
}

/// A query in progress ([`Bvh::visit`]): the ray prepared for the box and triangle tests, the
/// nearest hit so far, the node to visit next and how many entries its stack holds.
struct Walk {
    slab: SlabRay,
    pack_ray: PackRay,
    t_max: f32,
    nearest: Option<(u32, TriangleHit)>,
    node: NodeRef,
    depth: usize,
}

impl Walk {
    #[inline(always)]
    fn new(root: NodeRef, ray: &Ray, watertight: &WatertightRay) -> Walk {
        Walk {
            slab: SlabRay::new(ray),
            pack_ray: PackRay::new(watertight),
            t_max: ray.t_max,
            nearest: None,
            node: root,
            depth: 0,
        }
    }
}

/// The most rays [`Bvh::closest_hits`] traces together.
pub const MAX_INTERLEAVED: usize = 16;

/// The exit distances are enlarged by this factor (pbrt-v4 §6.8.2).
const ROBUST_EXIT: f32 = 1.0 + 2.0 * gamma(3);

impl SlabRay {
    #[inline]
    fn new(ray: &Ray) -> SlabRay {
        let d = ray.d.to_array();
        // A zero component would make (bound − o)/d a 0·∞; a tiny one keeps the test finite.
        let inv_dir = d.map(|c| {
            let c = if c.abs() < 1e-30 {
                1e-30f32.copysign(c)
            } else {
                c
            };
            1.0 / c
        });
        // The near bound follows the sign of 1/d (so a direction component of −0 enters
        // through the upper bound, as its −10³⁰ reciprocal says).
        let near = [0, 1, 2].map(|a| if inv_dir[a] > 0.0 { a } else { 3 + a });
        SlabRay {
            origin: ray.o.to_array(),
            inv_dir,
            near,
            far: near.map(|n| if n < 3 { n + 3 } else { n - 3 }),
        }
    }

    /// Entry distances of the children, and the mask of those entered within (0, t_max): AVX
    /// where `AVX` says the processor has it (one instruction per step for all eight
    /// children), else the portable SIMD of the `wide` crate (two SSE or NEON instructions per
    /// step). Both give the same bits.
    #[inline(always)]
    fn test<const AVX: bool>(&self, node: &Node, t_max: f32) -> ([f32; NODE_WIDTH], u32) {
        #[cfg(target_arch = "x86_64")]
        if AVX {
            // SAFETY: AVX is true only in code reached after checking that the processor has
            // AVX (see `Bvh::avx`).
            return unsafe { self.test_avx(node, t_max) };
        }
        let slab = |i: usize, axis: usize| {
            (node.bounds[i] - Lanes::splat(self.origin[axis])) * Lanes::splat(self.inv_dir[axis])
        };
        let t_near = slab(self.near[0], 0)
            .fast_max(slab(self.near[1], 1))
            .fast_max(slab(self.near[2], 2))
            .fast_max(Lanes::ZERO);
        let t_far = slab(self.far[0], 0)
            .fast_min(slab(self.far[1], 1))
            .fast_min(slab(self.far[2], 2))
            * Lanes::splat(ROBUST_EXIT);
        let t_far = t_far.fast_min(Lanes::splat(t_max));
        (t_near.to_array(), t_near.cmp_le(t_far).move_mask() as u32)
    }

    /// [`Self::test`] in AVX; the processor must have AVX.
    #[cfg(target_arch = "x86_64")]
    #[inline(always)]
    unsafe fn test_avx(&self, node: &Node, t_max: f32) -> ([f32; NODE_WIDTH], u32) {
        use std::arch::x86_64::*;
        // SAFETY: the caller guarantees AVX; `Node` is 64-byte aligned and its bounds are six
        // consecutive rows of eight f32, so every load is aligned and in bounds.
        unsafe {
            let bounds = node.bounds.as_ptr() as *const f32;
            let slab = |i: usize, axis: usize| {
                _mm256_mul_ps(
                    _mm256_sub_ps(
                        _mm256_load_ps(bounds.add(NODE_WIDTH * i)),
                        _mm256_set1_ps(self.origin[axis]),
                    ),
                    _mm256_set1_ps(self.inv_dir[axis]),
                )
            };
            let t_near = _mm256_max_ps(
                _mm256_max_ps(
                    _mm256_max_ps(slab(self.near[0], 0), slab(self.near[1], 1)),
                    slab(self.near[2], 2),
                ),
                _mm256_setzero_ps(),
            );
            let t_far = _mm256_mul_ps(
                _mm256_min_ps(
                    _mm256_min_ps(slab(self.far[0], 0), slab(self.far[1], 1)),
                    slab(self.far[2], 2),
                ),
                _mm256_set1_ps(ROBUST_EXIT),
            );
            let t_far = _mm256_min_ps(t_far, _mm256_set1_ps(t_max));
            let mask = _mm256_movemask_ps(_mm256_cmp_ps::<_CMP_LE_OQ>(t_near, t_far)) as u32;
            let mut distances = [0.0f32; NODE_WIDTH];
            _mm256_storeu_ps(distances.as_mut_ptr(), t_near);
            (distances, mask)
        }
    }
}

impl Bvh {
    /// Builds the hierarchy; None for no primitives.
    pub fn build(primitives: &[BuildPrimitive]) -> Option<Bvh> {
        if primitives.is_empty() {
            return None;
        }
        let binary = binary_hierarchy(primitives);
        Some(Collapse::new(&binary, primitives).run())
    }

    /// The box around everything.
    pub fn bounds(&self) -> (Vec3, Vec3) {
        (self.lo, self.hi)
    }

    /// Bytes of heap memory held by nodes and packs.
    pub fn memory_bytes(&self) -> usize {
        self.nodes.capacity() * std::mem::size_of::<Node>()
            + self.packs.capacity() * std::mem::size_of::<TrianglePack>()
    }

    /// The nearest hit in (0, ray.t_max): the primitive's id and the hit (barycentrics zero for
    /// analytic primitives, which `analytic(id, t_max)` intersects).
    #[inline]
    pub fn closest_hit(
        &self,
        ray: &Ray,
        watertight: &WatertightRay,
        analytic: impl FnMut(u32, f32) -> Option<f32>,
    ) -> Option<(u32, TriangleHit)> {
        self.traverse::<false>(ray, watertight, analytic)
    }

    /// Whether any primitive is hit in (0, ray.t_max).
    #[inline]
    pub fn occluded(
        &self,
        ray: &Ray,
        watertight: &WatertightRay,
        analytic: impl FnMut(u32, f32) -> Option<f32>,
    ) -> bool {
        self.traverse::<true>(ray, watertight, analytic).is_some()
    }

    /// [`Self::nearest_first`] with an uninitialised traversal stack of [`Self::stack_size`]
    /// entries (on the machine stack where that is small enough, every hierarchy but
    /// pathological ones, else on the heap), in AVX where the processor has it.
    #[inline(always)]
    fn traverse<const ANY_HIT: bool>(
        &self,
        ray: &Ray,
        watertight: &WatertightRay,
        analytic: impl FnMut(u32, f32) -> Option<f32>,
    ) -> Option<(u32, TriangleHit)> {
        let mut inline_stack = [MaybeUninit::uninit(); INLINE_STACK];
        let mut heap_stack = Vec::new();
        let stack = if self.stack_size <= INLINE_STACK {
            &mut inline_stack[..]
        } else {
            heap_stack.resize(self.stack_size, MaybeUninit::uninit());
            &mut heap_stack[..]
        };
        #[cfg(target_arch = "x86_64")]
        if self.avx {
            // SAFETY: `avx` is set only where the processor has AVX.
            return unsafe { self.nearest_first_avx::<ANY_HIT>(stack, ray, watertight, analytic) };
        }
        self.nearest_first::<false, ANY_HIT>(stack, ray, watertight, analytic)
    }

    /// [`Self::nearest_first`] compiled for AVX; the processor must have it.
    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx")]
    unsafe fn nearest_first_avx<const ANY_HIT: bool>(
        &self,
        stack: &mut [MaybeUninit<(NodeRef, f32)>],
        ray: &Ray,
        watertight: &WatertightRay,
        analytic: impl FnMut(u32, f32) -> Option<f32>,
    ) -> Option<(u32, TriangleHit)> {
        self.nearest_first::<true, ANY_HIT>(stack, ray, watertight, analytic)
    }

    /// The front-to-back traversal of both queries: the nearest hit, or with `ANY_HIT` the first
    /// one found. Shadow rays go nearest first too, which finds the occluders near their origin
    /// (the common case: the surroundings of the point lit) with the fewest leaves tested.
    #[inline(always)]
    fn nearest_first<const AVX: bool, const ANY_HIT: bool>(
        &self,
        stack: &mut [MaybeUninit<(NodeRef, f32)>],
        ray: &Ray,
        watertight: &WatertightRay,
        mut analytic: impl FnMut(u32, f32) -> Option<f32>,
    ) -> Option<(u32, TriangleHit)> {
        let mut walk = Walk::new(self.root, ray, watertight);
        while self.visit::<AVX, ANY_HIT>(&mut walk, stack, &mut analytic) {}
        walk.nearest
    }

    /// The nearest hits of `rays` (at most [`MAX_INTERLEAVED`]; None where there is no ray,
    /// whose hit is None), written to `hits`, their traversals interleaved: each ray visits
    /// one node and asks for the next node it will visit to be loaded, then the next ray takes
    /// its turn, so that the rays' cache misses overlap instead of following one another.
    /// `analytic(i, id, t_max)` intersects analytic primitive `id` with ray i. Each ray's
    /// result is the one [`Self::closest_hit`] gives. Hierarchies too deep for the stacks on
    /// the machine stack are traversed one ray after another.
    pub fn closest_hits(
        &self,
        rays: &[Option<&Ray>],
        mut analytic: impl FnMut(usize, u32, f32) -> Option<f32>,
        hits: &mut [Option<(u32, TriangleHit)>],
    ) {
        assert!(rays.len() <= MAX_INTERLEAVED && hits.len() == rays.len());
        if self.stack_size > INLINE_STACK {
            for (i, (ray, hit)) in rays.iter().zip(hits.iter_mut()).enumerate() {
                *hit = ray.and_then(|ray| {
                    let watertight = WatertightRay::new(ray.o, ray.d);
                    self.closest_hit(ray, &watertight, |id, t| analytic(i, id, t))
                });
            }
            return;
        }
        #[cfg(target_arch = "x86_64")]
        if self.avx {
            // SAFETY: `avx` is set only where the processor has AVX.
            return unsafe { self.interleaved_avx(rays, analytic, hits) };
        }
        self.interleaved::<false>(rays, analytic, hits);
    }

    /// [`Self::interleaved`] compiled for AVX; the processor must have it.
    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx")]
    unsafe fn interleaved_avx(
        &self,
        rays: &[Option<&Ray>],
        analytic: impl FnMut(usize, u32, f32) -> Option<f32>,
        hits: &mut [Option<(u32, TriangleHit)>],
    ) {
        self.interleaved::<true>(rays, analytic, hits);
    }

    /// The rays' walks taking turns, one node per ray per turn, until every ray is done.
    #[inline(always)]
    fn interleaved<const AVX: bool>(
        &self,
        rays: &[Option<&Ray>],
        mut analytic: impl FnMut(usize, u32, f32) -> Option<f32>,
        hits: &mut [Option<(u32, TriangleHit)>],
    ) {
        let mut stacks = [[MaybeUninit::uninit(); INLINE_STACK]; MAX_INTERLEAVED];
        let mut walks: [MaybeUninit<Walk>; MAX_INTERLEAVED] =
            [const { MaybeUninit::uninit() }; MAX_INTERLEAVED];
        let mut pending = 0u32;
        for (i, (walk, ray)) in walks.iter_mut().zip(rays).enumerate() {
            hits[i] = None;
            if let Some(ray) = ray {
                walk.write(Walk::new(self.root, ray, &WatertightRay::new(ray.o, ray.d)));
                pending |= 1 << i;
            }
        }
        while pending != 0 {
            let mut turn = pending;
            while turn != 0 {
                let i = turn.trailing_zeros() as usize;
                turn &= turn - 1;
                // SAFETY: the walks of the rays in `pending` were written above.
                let walk = unsafe { walks[i].assume_init_mut() };
                let goes_on =
                    self.visit::<AVX, false>(walk, &mut stacks[i], &mut |id, t| analytic(i, id, t));
                if !goes_on {
                    hits[i] = walk.nearest;
                    pending &= !(1 << i);
                }
            }
        }
    }

    /// One step of a query's front-to-back walk: visits the walk's node (an inner node's
    /// children the ray enters within its nearest hit so far, the nearest one next and the
    /// others pushed onto `stack`, farthest first; a leaf's primitives) and moves on to the
    /// next node, popping pending children the ray can no longer reach first. Returns false
    /// when the query is done (no node left, or with `ANY_HIT` a hit found).
    #[inline(always)]
    fn visit<const AVX: bool, const ANY_HIT: bool>(
        &self,
        walk: &mut Walk,
        stack: &mut [MaybeUninit<(NodeRef, f32)>],
        analytic: &mut impl FnMut(u32, f32) -> Option<f32>,
    ) -> bool {
        if walk.node.is_inner() {
            let n = &self.nodes[walk.node.0 as usize];
            let (t_near, mut mask) = walk.slab.test::<AVX>(n, walk.t_max);
            if mask != 0 {
                let first = mask.trailing_zeros() as usize;
                mask &= mask - 1;
                if mask == 0 {
                    walk.node = n.children[first];
                    self.prefetch(walk.node);
                    return true;
                }
                // Two or more children: sorted by entry distance, the nearest visited next.
                let mut hits = [(NodeRef(0), 0.0f32); NODE_WIDTH];
                hits[0] = (n.children[first], t_near[first]);
                let mut count = 1;
                while mask != 0 {
                    let i = mask.trailing_zeros() as usize;
                    mask &= mask - 1;
                    let entry = (n.children[i], t_near[i]);
                    let mut j = count;
                    while j > 0 && hits[j - 1].1 < entry.1 {
                        hits[j] = hits[j - 1];
                        j -= 1;
                    }
                    hits[j] = entry;
                    count += 1;
                }
                // `hits` is farthest first: push all but the last, visit the last. The pushed
                // nodes are fetched into the cache meanwhile.
                for &(pending, _) in &hits[..count - 1] {
                    self.prefetch(pending);
                }
                for (slot, &entry) in stack[walk.depth..].iter_mut().zip(&hits[..count - 1]) {
                    slot.write(entry);
                }
                walk.depth += count - 1;
                walk.node = hits[count - 1].0;
                self.prefetch(walk.node);
                return true;
            }
        } else if let Some((id, hit)) =
            self.leaf_hit(walk.node, &walk.pack_ray, walk.t_max, analytic)
        {
            walk.t_max = hit.t;
            walk.nearest = Some((id, hit));
            if ANY_HIT {
                return false;
            }
        }
        // Back up to the nearest pending child the ray can still reach first.
        while walk.depth > 0 {
            walk.depth -= 1;
            // SAFETY: the entries below `depth` have all been written.
            let (pending, t_entry) = unsafe { stack[walk.depth].assume_init() };
            if t_entry <= walk.t_max {
                walk.node = pending;
                return true;
            }
        }
        false
    }

    /// Asks the processor to start loading a child: an inner node or a leaf's triangle pack.
    #[inline(always)]
    fn prefetch(&self, node: NodeRef) {
        #[cfg(target_arch = "x86_64")]
        {
            use std::arch::x86_64::{_MM_HINT_T0, _mm_prefetch};
            let (start, bytes) = if node.is_inner() {
                let p = self.nodes.as_ptr().wrapping_add(node.0 as usize);
                (p as *const i8, std::mem::size_of::<Node>())
            } else if node.0 & ANALYTIC == 0 {
                let p = self
                    .packs
                    .as_ptr()
                    .wrapping_add((node.0 & PACK_INDEX_MASK) as usize);
                (p as *const i8, std::mem::size_of::<TrianglePack>())
            } else {
                return;
            };
            for offset in (0..bytes).step_by(64) {
                // SAFETY: prefetching is a hint; it never faults, whatever the address.
                unsafe { _mm_prefetch::<_MM_HINT_T0>(start.wrapping_add(offset)) };
            }
        }
    }

    #[inline(always)]
    fn leaf_hit(
        &self,
        leaf: NodeRef,
        ray: &PackRay,
        t_max: f32,
        analytic: &mut impl FnMut(u32, f32) -> Option<f32>,
    ) -> Option<(u32, TriangleHit)> {
        if leaf.0 & ANALYTIC != 0 {
            let id = leaf.0 & !(LEAF | ANALYTIC);
            return analytic(id, t_max).filter(|&t| t < t_max).map(|t| {
                (
                    id,
                    TriangleHit {
                        t,
                        b0: 0.0,
                        b1: 0.0,
                        b2: 0.0,
                    },
                )
            });
        }
        let pack = &self.packs[(leaf.0 & PACK_INDEX_MASK) as usize];
        let lanes = (leaf.0 >> LANES_SHIFT) & 0xF;
        pack.intersect(ray, lanes, t_max)
            .map(|(lane, hit)| (pack.id[lane], hit))
    }
}

/// The binary hierarchy that the wide one is collapsed from (one primitive per leaf).
fn binary_hierarchy(primitives: &[BuildPrimitive]) -> Bvh2 {
    let boxes: Vec<Aabb> = primitives.iter().map(BuildPrimitive::aabb).collect();
    let mut binary = PlocBuilder::with_capacity(boxes.len()).build(
        PlocSearchDistance::Medium,
        &boxes,
        (0..boxes.len() as u32).collect(),
        SortPrecision::U64,
        3,
    );
    ReinsertionOptimizer::default().run(&mut binary, 0.05, None);
    binary
}

/// Whether the processor running us has AVX (checked once per hierarchy, not per query).
fn has_avx() -> bool {
    #[cfg(target_arch = "x86_64")]
    return std::arch::is_x86_feature_detected!("avx");
    #[cfg(not(target_arch = "x86_64"))]
    false
}

/// A binary node waiting to become a child of the wide tree.
struct Pending {
    binary: usize,
    /// Where its reference goes: None for the subtree's root, else the wide node and slot.
    parent: Option<(usize, usize)>,
    depth: usize,
}

/// The collapse of a binary hierarchy into the 8-wide one. First every binary node is planned
/// (see [`Plan`]), children before parents, the halves of the top levels in parallel. Then
/// the root's children are collapsed in parallel (in trees of [`PARALLEL_COLLAPSE_NODES`]
/// binary nodes or more), each into a [`WideTree`] of its own, and the trees are laid end to
/// end (so nodes and packs stay in depth-first order).
struct Collapse<'a> {
    binary: &'a Bvh2,
    primitives: &'a [BuildPrimitive],
    /// Whether every primitive is a triangle (then no leaf needs to look at its primitives'
    /// kind to know that it may become a pack).
    only_triangles: bool,
    /// The [`Plan`] of every binary node, as `Plan::to_bits`.
    plans: Vec<AtomicU64>,
}

/// The wide nodes and packs of one subtree; its references are local (node and pack indices
/// from 0) until [`WideTree::rebase`] moves them to where the subtree lands.
#[derive(Default)]
struct WideTree {
    nodes: Vec<Node>,
    packs: Vec<TrianglePack>,
    /// The most recent packs with free lanes, and how many lanes of each are taken.
    open_packs: Vec<(usize, usize)>,
    /// Depth of the deepest node or leaf below the subtree's root (0 for the root itself).
    max_depth: usize,
}

/// Binary nodes from which the tree is planned and the root's subtrees are collapsed in
/// parallel: below, handing them to the thread pool costs more than it saves.
const PARALLEL_COLLAPSE_NODES: usize = 1 << 15;

/// How many recent packs a new leaf may go into (first fit): more fill packs better, fewer keep
/// a leaf's triangles near its siblings'.
const OPEN_PACKS: usize = 8;

/// Levels of the binary tree below the root whose halves are planned in parallel (2⁴ tasks).
const PARALLEL_PLAN_DEPTH: usize = 4;

/// The SAH costs of testing a wide node's boxes and of a leaf's pack, per unit of the surface
/// area of the box that leads to them (a ray meets a box with a probability proportional to
/// its area).
const NODE_COST: f32 = 1.0;
const LEAF_COST: f32 = 1.0;

/// How a binary subtree becomes children of the wide tree: the collapse that minimises the SAH
/// cost (Ylitie, Karras & Laine 2017, "Efficient Incoherent Ray Traversal on GPUs Through
/// Compressed Wide BVHs", §3.1), computed for every binary node n, children first:
///
/// - C(n, 1) = min(A(n)·c_leaf if n has at most four triangles, A(n)·c_node + S(n, 8)): the
///   subtree as one child, a leaf or a wide node;
/// - C(n, i) = min(C(n, 1), S(n, i)) for i = 2..8 free children, where
///   S(n, i) = min over 0 < k < i of C(left, k) + C(right, i − k) spreads it over its halves.
///
/// (S is non-increasing in i, so "fewer than i" needs no term of its own.) Leaves of one
/// primitive cost A·c_leaf however many children are free. Unlike the greedy collapse (open
/// the largest child until there are eight), this fills nodes with small subtrees' leaves
/// where that is cheaper than a node of their own.
#[derive(Clone, Copy, Debug)]
struct Plan {
    /// As one child: a wide node (true) or a leaf.
    node: bool,
    /// For i = 2..8 free children (index i − 1): the children its left half gets, the right
    /// half getting the rest; 0 where it stays one child.
    left_slots: [u8; NODE_WIDTH],
}

impl Plan {
    /// Eight bytes: `left_slots` with byte 0 (unused: one free child is one child) holding
    /// `node`.
    fn to_bits(self) -> u64 {
        let mut bytes = self.left_slots;
        bytes[0] = u8::from(self.node);
        u64::from_le_bytes(bytes)
    }

    fn from_bits(bits: u64) -> Plan {
        let mut left_slots = bits.to_le_bytes();
        let node = left_slots[0] != 0;
        left_slots[0] = 0;
        Plan { node, left_slots }
    }
}

/// What a binary subtree's parent needs to plan itself: C(n, i) for i = 1..8 (index i − 1),
/// and its triangles ([`NOT_A_PACK`] where more than a pack holds or not all are triangles).
struct SubtreeCost {
    cost: [f32; NODE_WIDTH],
    triangles: u8,
}

const NOT_A_PACK: u8 = PACK_WIDTH as u8 + 1;

impl<'a> Collapse<'a> {
    fn new(binary: &'a Bvh2, primitives: &'a [BuildPrimitive]) -> Collapse<'a> {
        let only_triangles = primitives
            .iter()
            .all(|p| matches!(p.kind, PrimitiveKind::Triangle(_)));
        let collapse = Collapse {
            binary,
            primitives,
            only_triangles,
            plans: (0..binary.nodes.len()).map(|_| AtomicU64::new(0)).collect(),
        };
        let parallel = binary.nodes.len() >= PARALLEL_COLLAPSE_NODES;
        collapse.plan(0, if parallel { PARALLEL_PLAN_DEPTH } else { 0 });
        collapse
    }

    fn plan_of(&self, i: usize) -> Plan {
        Plan::from_bits(self.plans[i].load(Ordering::Relaxed))
    }

    /// Plans the subtree under binary node `i` (see [`Plan`]) and returns its costs: its
    /// halves planned in parallel down `parallel_depth` more levels, the rest in one go.
    fn plan(&self, i: usize, parallel_depth: usize) -> SubtreeCost {
        let node = &self.binary.nodes[i];
        if parallel_depth == 0 || node.prim_count != 0 {
            return self.plan_in_one_go(i);
        }
        let first = node.first_index as usize;
        let (left, right) = rayon::join(
            || self.plan(first, parallel_depth - 1),
            || self.plan(first + 1, parallel_depth - 1),
        );
        self.plan_node(i, &left, &right)
    }

    /// [`Self::plan`] without threads: children before parents, with an explicit stack
    /// (binary trees can be deep).
    fn plan_in_one_go(&self, i: usize) -> SubtreeCost {
        let mut work = vec![(i, false)];
        let mut planned: Vec<SubtreeCost> = Vec::new();
        while let Some((i, children_planned)) = work.pop() {
            let node = &self.binary.nodes[i];
            if node.prim_count != 0 {
                planned.push(self.binary_leaf_cost(i));
            } else if children_planned {
                let right = planned.pop().expect("the right child was planned");
                let left = planned.pop().expect("the left child was planned");
                planned.push(self.plan_node(i, &left, &right));
            } else {
                let first = node.first_index as usize;
                work.extend([(i, true), (first + 1, false), (first, false)]);
            }
        }
        planned.pop().expect("the subtree was planned")
    }

    /// The costs of a leaf of the binary tree (it holds one primitive: PLOC makes such leaves),
    /// whose plan is the default one: a leaf however many children are free.
    fn binary_leaf_cost(&self, i: usize) -> SubtreeCost {
        let area = self.binary.nodes[i].aabb().half_area();
        let triangles_only = self.only_triangles
            || self
                .leaf_primitives(i)
                .iter()
                .all(|&p| matches!(self.primitives[p as usize].kind, PrimitiveKind::Triangle(_)));
        let count = self.binary.nodes[i].prim_count as usize;
        SubtreeCost {
            cost: [area * LEAF_COST; NODE_WIDTH],
            triangles: if triangles_only && count <= PACK_WIDTH {
                count as u8
            } else {
                NOT_A_PACK
            },
        }
    }

    /// Plans inner binary node `i` from its children's costs (the recurrence of [`Plan`]),
    /// stores the plan and returns the costs.
    fn plan_node(&self, i: usize, left: &SubtreeCost, right: &SubtreeCost) -> SubtreeCost {
        let area = self.binary.nodes[i].aabb().half_area();
        let triangles = (left.triangles + right.triangles).min(NOT_A_PACK);
        // The cheapest way to spread the subtree over up to `slots` children (index slots − 1),
        // and the slots its left half gets for that (some split even where every cost is
        // infinite: boxes of huge coordinates have infinite areas).
        let mut spread = [f32::INFINITY; NODE_WIDTH];
        let mut left_slots = [0u8; NODE_WIDTH];
        for slots in 2..=NODE_WIDTH {
            for k in 1..slots {
                let cost = left.cost[k - 1] + right.cost[slots - k - 1];
                if k == 1 || cost < spread[slots - 1] {
                    spread[slots - 1] = cost;
                    left_slots[slots - 1] = k as u8;
                }
            }
        }
        let leaf = if usize::from(triangles) <= PACK_WIDTH {
            area * LEAF_COST
        } else {
            f32::INFINITY
        };
        let node = area * NODE_COST + spread[NODE_WIDTH - 1];
        let mut plan = Plan {
            // A subtree that cannot be a leaf is a node, whatever the (perhaps infinite) costs.
            node: usize::from(triangles) > PACK_WIDTH || node < leaf,
            left_slots: [0; NODE_WIDTH],
        };
        let one_child = node.min(leaf);
        let mut cost = [one_child; NODE_WIDTH];
        for slots in 2..=NODE_WIDTH {
            if spread[slots - 1] <= one_child {
                cost[slots - 1] = spread[slots - 1];
                plan.left_slots[slots - 1] = left_slots[slots - 1];
            }
        }
        // A node's own children are its halves' spread over eight, even where a NaN cost (the
        // area of a flat box of infinite extent) compared false above. (No parent gives a child
        // all eight slots, so this entry is read for nodes only.)
        if plan.node {
            plan.left_slots[NODE_WIDTH - 1] = left_slots[NODE_WIDTH - 1];
        }
        self.plans[i].store(plan.to_bits(), Ordering::Relaxed);
        SubtreeCost { cost, triangles }
    }

    fn leaf_primitives(&self, i: usize) -> &'a [u32] {
        let node = &self.binary.nodes[i];
        let first = node.first_index as usize;
        &self.binary.primitive_indices[first..first + node.prim_count as usize]
    }

    /// The triangles below binary node `i` if it becomes a leaf of triangles: at most
    /// PACK_WIDTH primitives below it, all triangles. The walk stops as soon as it has seen
    /// more, so it costs a few nodes however large the subtree.
    fn triangle_leaf_primitives(&self, i: usize) -> Option<([u32; PACK_WIDTH], usize)> {
        let mut triangles = [0u32; PACK_WIDTH];
        let mut found = 0;
        // Every node on the stack has at least one primitive below it that is not yet counted,
        // so the stack never holds more than PACK_WIDTH entries while found ≤ PACK_WIDTH.
        let mut stack = [0usize; PACK_WIDTH];
        let mut depth = 1;
        stack[0] = i;
        while depth > 0 {
            depth -= 1;
            let node = &self.binary.nodes[stack[depth]];
            if node.prim_count == 0 {
                if found + depth + 2 > PACK_WIDTH {
                    return None;
                }
                stack[depth] = node.first_index as usize + 1;
                stack[depth + 1] = node.first_index as usize;
                depth += 2;
            } else {
                let leaf = self.leaf_primitives(stack[depth]);
                if found + leaf.len() > PACK_WIDTH {
                    return None;
                }
                for &p in leaf {
                    if !self.only_triangles
                        && !matches!(self.primitives[p as usize].kind, PrimitiveKind::Triangle(_))
                    {
                        return None;
                    }
                    triangles[found] = p;
                    found += 1;
                }
            }
        }
        Some((triangles, found))
    }

    fn run(self) -> Bvh {
        let root_box = self.binary.nodes[0].aabb();
        let children = if self.binary.nodes.len() < PARALLEL_COLLAPSE_NODES {
            None
        } else {
            self.node_children(0)
        };
        let (root, nodes, packs, max_depth) = match children {
            None => {
                let mut tree = WideTree::default();
                let root = tree.collapse(&self, 0);
                tree.nodes.shrink_to_fit();
                tree.packs.shrink_to_fit();
                (root, tree.nodes, tree.packs, tree.max_depth)
            }
            Some((children, count)) => {
                let subtrees: Vec<(NodeRef, WideTree)> = children[..count]
                    .par_iter()
                    .map(|&c| {
                        let mut tree = WideTree::default();
                        let root = tree.collapse(&self, c);
                        (root, tree)
                    })
                    .collect();
                let mut tree = WideTree::default();
                tree.push_node(&self, &children[..count]);
                let node_total = 1 + subtrees.iter().map(|(_, t)| t.nodes.len()).sum::<usize>();
                let pack_total = subtrees.iter().map(|(_, t)| t.packs.len()).sum::<usize>();
                tree.nodes.reserve_exact(node_total - 1);
                tree.packs.reserve_exact(pack_total);
                for (slot, (subtree_root, mut subtree)) in subtrees.into_iter().enumerate() {
                    let (node_offset, pack_offset) = (tree.nodes.len(), tree.packs.len());
                    tree.nodes[0].children[slot] =
                        subtree.rebase(subtree_root, node_offset, pack_offset);
                    tree.max_depth = tree.max_depth.max(subtree.max_depth + 1);
                    tree.nodes.append(&mut subtree.nodes);
                    tree.packs.append(&mut subtree.packs);
                }
                (NodeRef::inner(0), tree.nodes, tree.packs, tree.max_depth)
            }
        };
        let mut bvh = Bvh {
            nodes,
            packs,
            root,
            lo: Vec3::from(root_box.min),
            hi: Vec3::from(root_box.max),
            stack_size: (NODE_WIDTH - 1) * max_depth + 1,
            avx: has_avx(),
            built_cost: 0.0,
        };
        bvh.built_cost = bvh.sah_cost();
        bvh
    }

    /// The binary nodes that become the children of binary node `i` when it is an inner node
    /// of the wide tree, and how many; None where `i` becomes a leaf (as its [`Plan`] says).
    fn node_children(&self, i: usize) -> Option<([usize; NODE_WIDTH], usize)> {
        let plan = self.plan_of(i);
        if !plan.node {
            return None;
        }
        let mut children = ([0usize; NODE_WIDTH], 0);
        let first = self.binary.nodes[i].first_index as usize;
        let left_slots = usize::from(plan.left_slots[NODE_WIDTH - 1]);
        self.spread(first, left_slots, &mut children);
        self.spread(first + 1, NODE_WIDTH - left_slots, &mut children);
        Some(children)
    }

    /// Appends to `children` the binary nodes that the subtree under `i` spreads into when
    /// `slots` children are free for it (as its [`Plan`] says).
    fn spread(&self, i: usize, slots: usize, children: &mut ([usize; NODE_WIDTH], usize)) {
        let left_slots = match slots {
            1 => 0,
            _ => usize::from(self.plan_of(i).left_slots[slots - 1]),
        };
        if left_slots == 0 {
            children.0[children.1] = i;
            children.1 += 1;
        } else {
            let first = self.binary.nodes[i].first_index as usize;
            self.spread(first, left_slots, children);
            self.spread(first + 1, slots - left_slots, children);
        }
    }
}

impl WideTree {
    /// Collapses the binary subtree under node `i` into this tree; returns its root's reference.
    fn collapse(&mut self, collapse: &Collapse, i: usize) -> NodeRef {
        let mut root = NodeRef(0);
        // Depth first, with an explicit stack (binary trees can be deep). Children are pushed
        // last first, so nodes and packs are laid out in depth-first order.
        let mut work = vec![Pending {
            binary: i,
            parent: None,
            depth: 0,
        }];
        while let Some(Pending {
            binary: i,
            parent,
            depth,
        }) = work.pop()
        {
            self.max_depth = self.max_depth.max(depth);
            let reference = match collapse.node_children(i) {
                None => self.leaf(collapse, i),
                Some((children, count)) => {
                    let index = self.push_node(collapse, &children[..count]);
                    for slot in (0..count).rev() {
                        work.push(Pending {
                            binary: children[slot],
                            parent: Some((index, slot)),
                            depth: depth + 1,
                        });
                    }
                    NodeRef::inner(index)
                }
            };
            match parent {
                None => root = reference,
                Some((node, slot)) => self.nodes[node].children[slot] = reference,
            }
        }
        root
    }

    /// Moves the tree's references to a tree whose nodes start at `node_offset` and whose packs
    /// start at `pack_offset`; returns `root` moved likewise.
    fn rebase(&mut self, root: NodeRef, node_offset: usize, pack_offset: usize) -> NodeRef {
        let moved = |r: NodeRef| {
            if r.is_inner() {
                NodeRef::inner(r.0 as usize + node_offset)
            } else if r.0 & ANALYTIC == 0 {
                let pack = (r.0 & PACK_INDEX_MASK) as usize + pack_offset;
                NodeRef::triangles(pack, (r.0 >> LANES_SHIFT) & 0xF)
            } else {
                r
            }
        };
        for node in &mut self.nodes {
            node.children = node.children.map(moved);
        }
        moved(root)
    }

    /// Appends a wide node over the boxes of binary nodes `children` (its references are set
    /// later); returns its index. Empty slots keep inverted boxes and a reference no ray reads.
    fn push_node(&mut self, collapse: &Collapse, children: &[usize]) -> usize {
        let mut bounds = [
            [f32::INFINITY; NODE_WIDTH],
            [f32::INFINITY; NODE_WIDTH],
            [f32::INFINITY; NODE_WIDTH],
            [f32::NEG_INFINITY; NODE_WIDTH],
            [f32::NEG_INFINITY; NODE_WIDTH],
            [f32::NEG_INFINITY; NODE_WIDTH],
        ];
        for (slot, &c) in children.iter().enumerate() {
            let aabb = collapse.binary.nodes[c].aabb();
            for axis in 0..3 {
                bounds[axis][slot] = aabb.min[axis];
                bounds[3 + axis][slot] = aabb.max[axis];
            }
        }
        self.nodes.push(Node {
            bounds: bounds.map(Lanes::new),
            children: [NodeRef(0); NODE_WIDTH],
        });
        self.nodes.len() - 1
    }

    /// The leaf for binary node `i`: its triangles, or the analytic primitive of a binary leaf
    /// (the builder puts one primitive per leaf).
    fn leaf(&mut self, collapse: &Collapse, i: usize) -> NodeRef {
        if let Some((triangles, found)) = collapse.triangle_leaf_primitives(i) {
            return self.triangle_leaf(collapse, &triangles[..found]);
        }
        debug_assert_eq!(
            collapse.binary.nodes[i].prim_count, 1,
            "PLOC leaves hold one primitive"
        );
        let p = collapse.leaf_primitives(i)[0] as usize;
        NodeRef::analytic(collapse.primitives[p].id)
    }

    /// A leaf of (at most four) `triangles`, in a recent pack if they fit there, else in a new
    /// one.
    fn triangle_leaf(&mut self, collapse: &Collapse, triangles: &[u32]) -> NodeRef {
        let fits = self
            .open_packs
            .iter()
            .position(|&(_, used)| used + triangles.len() <= PACK_WIDTH);
        let slot = fits.unwrap_or_else(|| {
            if self.open_packs.len() == OPEN_PACKS {
                self.open_packs.remove(0);
            }
            self.packs.push(TrianglePack::empty());
            self.open_packs.push((self.packs.len() - 1, 0));
            self.open_packs.len() - 1
        });
        let (pack_index, used) = &mut self.open_packs[slot];
        let mut lanes = 0;
        for &p in triangles {
            let primitive = &collapse.primitives[p as usize];
            let PrimitiveKind::Triangle(vertices) = primitive.kind else {
                unreachable!("a triangle leaf holds triangles only");
            };
            self.packs[*pack_index].set(*used, vertices, primitive.id);
            lanes |= 1 << *used;
            *used += 1;
        }
        let leaf = NodeRef::triangles(*pack_index, lanes);
        if *used == PACK_WIDTH {
            self.open_packs.remove(slot);
        }
        leaf
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::sampling::rng::Pcg32;
    use std::collections::HashMap;

    pub(super) fn random_unit(rng: &mut Pcg32) -> Vec3 {
        Vec3::new(rng.next_f32(), rng.next_f32(), rng.next_f32()) * 2.0 - 1.0
    }

    /// Random small triangles in a cube, and some analytic "spheres" given by their boxes.
    pub(super) fn scene(
        rng: &mut Pcg32,
        triangles: usize,
    ) -> (Vec<BuildPrimitive>, Vec<(Vec3, f32)>) {
        let mut primitives = Vec::new();
        for id in 0..triangles {
            let c = random_unit(rng);
            let v = [0, 1, 2].map(|_| c + random_unit(rng) * 0.1);
            primitives.push(BuildPrimitive {
                id: id as u32,
                kind: PrimitiveKind::Triangle(v),
            });
        }
        let mut spheres = Vec::new();
        for k in 0..5 {
            let c = random_unit(rng);
            let r = 0.05 + 0.1 * rng.next_f32();
            spheres.push((c, r));
            primitives.push(BuildPrimitive {
                id: (triangles + k) as u32,
                kind: PrimitiveKind::Analytic {
                    lo: c - r,
                    hi: c + r,
                },
            });
        }
        (primitives, spheres)
    }

    pub(super) fn sphere_hit(ray: &Ray, (c, r): (Vec3, f32), t_max: f32) -> Option<f32> {
        let oc = ray.o - c;
        let a = ray.d.length_squared();
        let b = oc.dot(ray.d);
        let disc = b * b - a * (oc.length_squared() - r * r);
        if disc < 0.0 {
            return None;
        }
        let s = disc.sqrt();
        [(-b - s) / a, (-b + s) / a]
            .into_iter()
            .find(|&t| t > 0.0 && t < t_max)
    }

    /// The nearest hit and occlusion agree with testing every primitive, on random rays.
    #[test]
    fn agrees_with_brute_force() {
        let mut rng = Pcg32::seeded(5);
        // 20,000 triangles make a binary tree above PARALLEL_COLLAPSE_NODES, collapsed in
        // parallel; the others are collapsed in one piece.
        const { assert!(2 * 20_000 > PARALLEL_COLLAPSE_NODES) };
        for (triangles, rays) in [
            (1, 4000),
            (3, 4000),
            (4, 4000),
            (5, 4000),
            (17, 4000),
            (2000, 4000),
            (20_000, 400),
        ] {
            let (primitives, spheres) = scene(&mut rng, triangles);
            let bvh = Bvh::build(&primitives).unwrap();
            // No spare capacity: `memory_bytes` counts what is allocated.
            assert_eq!(bvh.nodes.capacity(), bvh.nodes.len());
            assert_eq!(bvh.packs.capacity(), bvh.packs.len());
            let analytic_of = |ray: Ray| {
                let spheres = spheres.clone();
                move |id: u32, t_max: f32| sphere_hit(&ray, spheres[id as usize - triangles], t_max)
            };
            let mut hits = 0;
            for k in 0..rays {
                let o = random_unit(&mut rng) * 2.0;
                // Most rays aim at a primitive; some are axis-aligned (zero direction
                // components), some go anywhere.
                let aim = match primitives[k % primitives.len()].kind {
                    PrimitiveKind::Triangle(v) => (v[0] + v[1] + v[2]) / 3.0,
                    PrimitiveKind::Analytic { lo, hi } => (lo + hi) / 2.0,
                };
                let d = match k % 10 {
                    // Zero components of either sign (−Z is (−0, −0, −1)).
                    0 if k % 20 == 0 => Vec3::Z,
                    0 => -Vec3::Z,
                    5 => Vec3::new(-0.0, random_unit(&mut rng).y, 0.0),
                    1 => random_unit(&mut rng),
                    _ => aim + random_unit(&mut rng) * 0.02 - o,
                };
                let t_max = if k % 2 == 0 { f32::INFINITY } else { 2.0 };
                let ray = Ray::new(o, d, t_max, 0.0);
                let watertight = WatertightRay::new(o, d);
                let mut expected: Option<(u32, f32)> = None;
                for p in &primitives {
                    let limit = expected.map_or(t_max, |e| e.1);
                    let t = match p.kind {
                        PrimitiveKind::Triangle(v) => {
                            watertight.intersect(limit, v[0], v[1], v[2]).map(|h| h.t)
                        }
                        PrimitiveKind::Analytic { .. } => {
                            sphere_hit(&ray, spheres[p.id as usize - triangles], limit)
                        }
                    };
                    if let Some(t) = t.filter(|&t| t < limit) {
                        expected = Some((p.id, t));
                    }
                }
                let found = bvh.closest_hit(&ray, &watertight, analytic_of(ray));
                assert_eq!(
                    found.map(|(_, h)| h.t),
                    expected.map(|e| e.1),
                    "{triangles} triangles, ray {k}"
                );
                assert_eq!(
                    bvh.occluded(&ray, &watertight, analytic_of(ray)),
                    expected.is_some()
                );
                hits += usize::from(expected.is_some());
            }
            assert!(hits > rays / 4, "{triangles} triangles: only {hits} hits");
        }
    }

    /// The portable and the AVX node tests find the same hits, bit for bit (on a processor
    /// without AVX both run the portable test).
    #[test]
    fn portable_and_avx_queries_agree() {
        let mut rng = Pcg32::seeded(7);
        let (primitives, _) = scene(&mut rng, 3000);
        let triangles = &primitives[..3000];
        let mut portable = Bvh::build(triangles).unwrap();
        portable.avx = false;
        let mut avx = portable.clone();
        avx.avx = has_avx();
        let none = |_: u32, _: f32| None;
        for _ in 0..20_000 {
            let o = random_unit(&mut rng) * 2.0;
            let d = random_unit(&mut rng) - o * 0.5;
            let ray = Ray::new(o, d, f32::INFINITY, 0.0);
            let watertight = WatertightRay::new(o, d);
            assert_eq!(
                portable.closest_hit(&ray, &watertight, none),
                avx.closest_hit(&ray, &watertight, none)
            );
            assert_eq!(
                portable.occluded(&ray, &watertight, none),
                avx.occluded(&ray, &watertight, none)
            );
        }
    }

    /// Interleaved closest-hit queries of up to [`MAX_INTERLEAVED`] rays, some lanes empty, give
    /// each ray what its query alone gives, bit for bit, with analytic primitives and both node
    /// tests.
    #[test]
    fn interleaved_queries_agree_with_one_ray_queries() {
        let mut rng = Pcg32::seeded(23);
        for triangles in [1, 17, 3000] {
            let (primitives, spheres) = scene(&mut rng, triangles);
            let mut bvh = Bvh::build(&primitives).unwrap();
            for avx in [false, has_avx()] {
                bvh.avx = avx;
                let mut hits = 0;
                for group in 0..400 {
                    let width = 1 + group % MAX_INTERLEAVED;
                    let rays: Vec<Option<Ray>> = (0..width)
                        .map(|k| {
                            // Most rays aim at a primitive, some go anywhere.
                            let o = random_unit(&mut rng) * 2.0;
                            let aim = match primitives[(group + k) % primitives.len()].kind {
                                PrimitiveKind::Triangle(v) => (v[0] + v[1] + v[2]) / 3.0,
                                PrimitiveKind::Analytic { lo, hi } => (lo + hi) / 2.0,
                            };
                            let d = if k % 4 == 1 {
                                random_unit(&mut rng)
                            } else {
                                aim + random_unit(&mut rng) * 0.02 - o
                            };
                            let t_max = if k % 3 == 0 { 1.5 } else { f32::INFINITY };
                            (k % 5 != 4).then(|| Ray::new(o, d, t_max, 0.0))
                        })
                        .collect();
                    let refs: Vec<Option<&Ray>> = rays.iter().map(Option::as_ref).collect();
                    let analytic = |i: usize, id: u32, t_max: f32| {
                        sphere_hit(rays[i].as_ref()?, spheres[id as usize - triangles], t_max)
                    };
                    let stale = TriangleHit {
                        t: -1.0,
                        b0: 0.0,
                        b1: 0.0,
                        b2: 0.0,
                    };
                    let mut nearest = vec![Some((u32::MAX, stale)); width];
                    bvh.closest_hits(&refs, analytic, &mut nearest);
                    for (i, ray) in rays.iter().enumerate() {
                        let Some(ray) = ray else {
                            assert_eq!(nearest[i], None);
                            continue;
                        };
                        let watertight = WatertightRay::new(ray.o, ray.d);
                        let one = |id: u32, t: f32| analytic(i, id, t);
                        assert_eq!(nearest[i], bvh.closest_hit(ray, &watertight, one));
                        hits += usize::from(nearest[i].is_some());
                    }
                }
                assert!(hits > 500, "{triangles} triangles: only {hits} hits");
            }
        }
    }

    /// Every way to cover the binary subtree under `i` with at most `slots` of its nodes (each
    /// leaf of the subtree below exactly one of them).
    fn covers(binary: &Bvh2, i: usize, slots: usize) -> Vec<Vec<usize>> {
        let mut all = vec![vec![i]];
        let node = &binary.nodes[i];
        if node.prim_count == 0 && slots >= 2 {
            let first = node.first_index as usize;
            for left in covers(binary, first, slots - 1) {
                for right in covers(binary, first + 1, slots - left.len()) {
                    all.push([left.clone(), right].concat());
                }
            }
        }
        all
    }

    /// The least SAH cost of any 8-wide tree over the binary subtree under `i`, found by trying,
    /// for each wide node, every cover of its binary node's halves by at most eight nodes.
    /// Independent of the dynamic programme it checks, and exponential: small trees only.
    fn least_sah_cost(
        binary: &Bvh2,
        primitives: &[BuildPrimitive],
        i: usize,
        known: &mut HashMap<usize, f64>,
    ) -> f64 {
        if let Some(&least) = known.get(&i) {
            return least;
        }
        let node = &binary.nodes[i];
        let area = f64::from(node.aabb().half_area());
        let mut below: Vec<u32> = Vec::new();
        let mut work = vec![i];
        while let Some(n) = work.pop() {
            let n = &binary.nodes[n];
            if n.prim_count == 0 {
                work.extend([n.first_index as usize, n.first_index as usize + 1]);
            } else {
                let first = n.first_index as usize;
                below.extend(&binary.primitive_indices[first..first + n.prim_count as usize]);
            }
        }
        let all_triangles = below
            .iter()
            .all(|&p| matches!(primitives[p as usize].kind, PrimitiveKind::Triangle(_)));
        let mut least = f64::INFINITY;
        if node.prim_count != 0 || (all_triangles && below.len() <= PACK_WIDTH) {
            least = area * f64::from(LEAF_COST);
        }
        if node.prim_count == 0 {
            let first = node.first_index as usize;
            let halves = [first, first + 1];
            for left in covers(binary, halves[0], NODE_WIDTH - 1) {
                for right in covers(binary, halves[1], NODE_WIDTH - left.len()) {
                    let children: f64 = left
                        .iter()
                        .chain(&right)
                        .map(|&c| least_sah_cost(binary, primitives, c, known))
                        .sum();
                    least = least.min(area * f64::from(NODE_COST) + children);
                }
            }
        }
        known.insert(i, least);
        least
    }

    /// The collapse is the cheapest by the SAH: the built tree costs what an exhaustive search
    /// over all collapses of the same binary tree finds (to f32 rounding), on small scenes with
    /// and without analytic primitives.
    #[test]
    fn collapse_is_sah_optimal() {
        let mut rng = Pcg32::seeded(11);
        for triangles in [3, 9, 17, 30, 100, 300] {
            let (primitives, _) = scene(&mut rng, triangles);
            for primitives in [&primitives[..triangles], &primitives[..]] {
                let binary = binary_hierarchy(primitives);
                let least = least_sah_cost(&binary, primitives, 0, &mut HashMap::new());
                let built = Bvh::build(primitives).unwrap().sah_cost();
                // The plan sums its costs in f32: n terms (a few hundred here) rounded by
                // 6·10⁻⁸ relative each err by about √n · 6·10⁻⁸ < 2·10⁻⁶, so it may pick a tree
                // whose f64 cost is that much above the least; 10⁻⁵ leaves a factor five.
                assert!(
                    (built - least).abs() <= 1e-5 * least,
                    "{} primitives: the collapse costs {built}, the cheapest {least}",
                    primitives.len()
                );
            }
        }
    }

    /// Boxes so large that their surface areas overflow to infinity (a few triangles with
    /// coordinates near 10²⁰ among small ones), or are NaN (a flat box of infinite extent),
    /// still give a valid tree: every small triangle is found where testing them all finds it.
    /// (The huge ones overflow the triangle test itself, so no ray hits them.)
    #[test]
    fn infinite_surface_areas_give_a_valid_tree() {
        let mut rng = Pcg32::seeded(17);
        let (mut primitives, _) = scene(&mut rng, 60);
        primitives.truncate(60);
        for (k, p) in primitives.iter_mut().enumerate().take(3) {
            let PrimitiveKind::Triangle(v) = p.kind else {
                unreachable!("the first primitives are triangles")
            };
            p.kind = PrimitiveKind::Triangle(v.map(|x| x * 1e20 * (k + 1) as f32));
        }
        // A flat one whose box is infinitely wide: its area is ∞ · 0, NaN.
        primitives[3].kind = PrimitiveKind::Triangle([
            Vec3::new(-2e38, 0.0, 0.0),
            Vec3::new(2e38, 1.0, 0.0),
            Vec3::new(0.0, 2.0, 0.0),
        ]);
        let bvh = Bvh::build(&primitives).unwrap();
        let mut hits = 0;
        for p in &primitives[4..] {
            let PrimitiveKind::Triangle(v) = p.kind else {
                unreachable!("all primitives are triangles")
            };
            let o = Vec3::new(0.1, 0.2, 3.0);
            let d = (v[0] + v[1] + v[2]) / 3.0 - o;
            let (ray, watertight) = (Ray::new(o, d, f32::INFINITY, 0.0), WatertightRay::new(o, d));
            let expected = primitives
                .iter()
                .filter_map(|q| match q.kind {
                    PrimitiveKind::Triangle(w) => {
                        watertight.intersect(f32::INFINITY, w[0], w[1], w[2])
                    }
                    PrimitiveKind::Analytic { .. } => None,
                })
                .map(|h| h.t)
                .reduce(f32::min);
            let found = bvh.closest_hit(&ray, &watertight, |_, _| None);
            assert_eq!(found.map(|(_, h)| h.t), expected);
            hits += usize::from(found.is_some());
        }
        assert_eq!(
            hits,
            primitives.len() - 4,
            "every aimed ray hits a triangle"
        );
    }

    /// Packs are shared by small leaves: a large mesh needs few more packs than a quarter of its
    /// triangles.
    #[test]
    fn packs_are_nearly_full() {
        let mut rng = Pcg32::seeded(6);
        let (primitives, _) = scene(&mut rng, 20_000);
        let bvh = Bvh::build(&primitives[..20_000]).unwrap();
        let fill = 20_000.0 / (bvh.packs.len() * PACK_WIDTH) as f64;
        assert!(fill > 0.8, "packs are only {:.0} % full", fill * 100.0);
    }
}
