//! Colliders: shapes attached to bodies, stored in one `Vec` per shape kind.

use crate::fixed::check_extent;
use crate::shape::{Aabb, Circle, ConvexPolygon, Obb, Point, Segment, Shape, ShapeKind};
use glam::IVec2;
use serde::{Deserialize, Serialize};

pub use super::id::ColliderId;

use super::error::BuildError;
use super::id::BodyId;

/// Whether a collider blocks or only reports.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Serialize, Deserialize)]
pub enum ColliderMode {
    /// Pushes and is pushed.
    Solid,
    /// Raises [`super::Event::Trigger`] events and never moves anything.
    Trigger,
}

/// The side from which a one-way collider is solid, which is also the
/// direction it pushes: `Up` is a platform you can land on from above and
/// jump through from below.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Serialize, Deserialize)]
pub enum OneWay {
    /// Solid from above (`-y`), pushes up.
    Up,
    /// Solid from below (`+y`), pushes down.
    Down,
    /// Solid from the left (`-x`), pushes left.
    Left,
    /// Solid from the right (`+x`), pushes right.
    Right,
}

impl OneWay {
    /// The unit normal: the direction the collider pushes.
    #[inline]
    pub fn normal(self) -> IVec2 {
        match self {
            OneWay::Up => IVec2::new(0, -1),
            OneWay::Down => IVec2::new(0, 1),
            OneWay::Left => IVec2::new(-1, 0),
            OneWay::Right => IVec2::new(1, 0),
        }
    }

    /// The byte this direction hashes as (0 is "not one-way").
    pub(crate) fn code(dir: Option<OneWay>) -> u8 {
        match dir {
            None => 0,
            Some(OneWay::Up) => 1,
            Some(OneWay::Down) => 2,
            Some(OneWay::Left) => 3,
            Some(OneWay::Right) => 4,
        }
    }
}

/// Any shape, by value: used to describe colliders and to view them. The
/// simulation itself never matches on it.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Serialize, Deserialize)]
pub enum AnyShape {
    /// A point.
    Point(Point),
    /// A segment.
    Segment(Segment),
    /// A circle.
    Circle(Circle),
    /// An axis-aligned box.
    Aabb(Aabb),
    /// An oriented box.
    Obb(Obb),
    /// A convex polygon.
    Polygon(ConvexPolygon),
}

impl AnyShape {
    /// The shape's kind.
    pub fn kind(&self) -> ShapeKind {
        match self {
            AnyShape::Point(_) => ShapeKind::Point,
            AnyShape::Segment(_) => ShapeKind::Segment,
            AnyShape::Circle(_) => ShapeKind::Circle,
            AnyShape::Aabb(_) => ShapeKind::Aabb,
            AnyShape::Obb(_) => ShapeKind::Obb,
            AnyShape::Polygon(_) => ShapeKind::Polygon,
        }
    }

    /// Smallest and largest corner of the bounding box, in local units.
    pub fn local_bounds(&self) -> (IVec2, IVec2) {
        match self {
            AnyShape::Point(s) => s.local_bounds(),
            AnyShape::Segment(s) => s.local_bounds(),
            AnyShape::Circle(s) => s.local_bounds(),
            AnyShape::Aabb(s) => s.local_bounds(),
            AnyShape::Obb(s) => s.local_bounds(),
            AnyShape::Polygon(s) => s.local_bounds(),
        }
    }
}

macro_rules! any_shape_from {
    ($($t:ident => $v:ident),*) => {$(
        impl From<$t> for AnyShape {
            #[inline]
            fn from(s: $t) -> Self {
                AnyShape::$v(s)
            }
        }
    )*};
}
any_shape_from!(Point => Point, Segment => Segment, Circle => Circle, Aabb => Aabb, Obb => Obb, ConvexPolygon => Polygon);

/// What [`super::World::add_collider`] needs to attach a collider to a body.
///
/// Two colliders interact iff `a.layer & b.mask != 0 && b.layer & a.mask != 0`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
pub struct ColliderDesc {
    /// The shape, in local coordinates around the collider's origin.
    pub shape: AnyShape,
    /// The collider's origin relative to its body (each component within
    /// `±MAX_EXTENT`).
    pub offset: IVec2,
    /// Solid or trigger.
    pub mode: ColliderMode,
    /// Layers this collider is on (default: bit 0).
    pub layer: u32,
    /// Layers this collider interacts with (default: all).
    pub mask: u32,
    /// Solid only from one side (solid colliders only).
    pub one_way: Option<OneWay>,
    /// The user's type for this collider (wall, floor, ...), reported in events.
    pub tag: u16,
}

impl ColliderDesc {
    /// A solid collider at the body's origin, layer 1, all-layer mask, tag 0.
    pub fn solid(shape: impl Into<AnyShape>) -> Self {
        Self {
            shape: shape.into(),
            offset: IVec2::ZERO,
            mode: ColliderMode::Solid,
            layer: 1,
            mask: u32::MAX,
            one_way: None,
            tag: 0,
        }
    }

    /// A trigger collider at the body's origin, layer 1, all-layer mask, tag 0.
    pub fn trigger(shape: impl Into<AnyShape>) -> Self {
        Self {
            mode: ColliderMode::Trigger,
            ..Self::solid(shape)
        }
    }

    /// The same at `offset` from the body.
    pub fn at(mut self, offset: IVec2) -> Self {
        self.offset = offset;
        self
    }

    /// The same with tag `tag`.
    pub fn tagged(mut self, tag: u16) -> Self {
        self.tag = tag;
        self
    }

    /// The same on layers `layer`, interacting with layers `mask`.
    pub fn layers(mut self, layer: u32, mask: u32) -> Self {
        self.layer = layer;
        self.mask = mask;
        self
    }

    /// The same, solid only from side `dir`.
    pub fn one_way(mut self, dir: OneWay) -> Self {
        self.one_way = Some(dir);
        self
    }

    /// Checks the offset against the bounds.
    pub(crate) fn validate(&self) -> Result<(), BuildError> {
        check_extent("collider offset x", self.offset.x as i64)?;
        check_extent("collider offset y", self.offset.y as i64)?;
        if self.one_way.is_some() && self.mode == ColliderMode::Trigger {
            return Err(BuildError::OneWayTrigger);
        }
        Ok(())
    }
}

/// A collider as seen from outside the simulation (rendering, tests, tools).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct ColliderView {
    /// Its id.
    pub id: ColliderId,
    /// The body it is attached to.
    pub body: BodyId,
    /// Its origin in world units (body position plus offset): the shape is
    /// placed around this point.
    pub pos: IVec2,
    /// Its offset from the body.
    pub offset: IVec2,
    /// Its shape, in local coordinates around `pos`.
    pub shape: AnyShape,
    /// Solid or trigger.
    pub mode: ColliderMode,
    /// Layer bits.
    pub layer: u32,
    /// Mask bits.
    pub mask: u32,
    /// One-way side, if any.
    pub one_way: Option<OneWay>,
    /// The user's tag.
    pub tag: u16,
}

impl ColliderView {
    /// World-space bounding box `(min, max)`.
    pub fn world_bounds(&self) -> (IVec2, IVec2) {
        let (lo, hi) = self.shape.local_bounds();
        (self.pos + lo, self.pos + hi)
    }
}

/// One collider of shape `S` as the hot loops see it: everything a pair test
/// needs, without touching the body table for the early rejects.
#[derive(Debug, Clone, PartialEq, Eq)]
pub(crate) struct ColliderData<S> {
    pub id: u32,
    pub body: u32,
    pub offset: IVec2,
    pub shape: S,
    /// Local bounding box around the body position (shape bounds + offset).
    pub lo: IVec2,
    pub hi: IVec2,
    pub solid: bool,
    /// Whether its body is dynamic (body kinds never change).
    pub dynamic: bool,
    pub layer: u32,
    pub mask: u32,
    pub one_way: Option<OneWay>,
    pub tag: u16,
}

/// All colliders of one shape kind, in creation order.
#[derive(Debug, Clone, PartialEq, Eq)]
pub(crate) struct ColliderSet<S> {
    pub items: Vec<ColliderData<S>>,
}

impl<S> Default for ColliderSet<S> {
    fn default() -> Self {
        Self { items: Vec::new() }
    }
}

/// One [`ColliderSet`] per shape kind.
#[derive(Debug, Clone, Default, PartialEq, Eq)]
pub(crate) struct Colliders {
    pub points: ColliderSet<Point>,
    pub segments: ColliderSet<Segment>,
    pub circles: ColliderSet<Circle>,
    pub aabbs: ColliderSet<Aabb>,
    pub obbs: ColliderSet<Obb>,
    pub polygons: ColliderSet<ConvexPolygon>,
}

/// A shape kind that has a [`ColliderSet`] in [`Colliders`]: static dispatch
/// from a shape type to its storage.
pub(crate) trait Stored: Shape + Copy + Sized + 'static {
    fn set(c: &Colliders) -> &ColliderSet<Self>;
    fn set_mut(c: &mut Colliders) -> &mut ColliderSet<Self>;
    fn any(self) -> AnyShape;
}

macro_rules! stored {
    ($($t:ident => $field:ident),*) => {$(
        impl Stored for $t {
            #[inline(always)]
            fn set(c: &Colliders) -> &ColliderSet<Self> {
                &c.$field
            }
            #[inline(always)]
            fn set_mut(c: &mut Colliders) -> &mut ColliderSet<Self> {
                &mut c.$field
            }
            #[inline(always)]
            fn any(self) -> AnyShape {
                self.into()
            }
        }
    )*};
}
stored!(Point => points, Segment => segments, Circle => circles, Aabb => aabbs, Obb => obbs, ConvexPolygon => polygons);

impl Colliders {
    /// Appends a collider of shape `S`; returns its index in its set.
    pub fn push<S: Stored>(&mut self, data: ColliderData<S>) -> u32 {
        let set = S::set_mut(self);
        set.items.push(data);
        (set.items.len() - 1) as u32
    }

    /// Total number of colliders.
    pub fn len(&self) -> usize {
        self.points.items.len()
            + self.segments.items.len()
            + self.circles.items.len()
            + self.aabbs.items.len()
            + self.obbs.items.len()
            + self.polygons.items.len()
    }
}

/// Builds the hot-loop record for `shape` (the description is validated).
pub(crate) fn make_data<S: Stored>(
    id: u32,
    body: u32,
    dynamic: bool,
    shape: S,
    desc: &ColliderDesc,
) -> ColliderData<S> {
    let (lo, hi) = shape.local_bounds();
    ColliderData {
        id,
        body,
        offset: desc.offset,
        shape,
        lo: lo + desc.offset,
        hi: hi + desc.offset,
        solid: desc.mode == ColliderMode::Solid,
        dynamic,
        layer: desc.layer,
        mask: desc.mask,
        one_way: desc.one_way,
        tag: desc.tag,
    }
}

/// The outside view of a stored collider, given its body's position.
pub(crate) fn view<S: Stored>(d: &ColliderData<S>, body_pos: IVec2) -> ColliderView {
    ColliderView {
        id: ColliderId(d.id),
        body: BodyId(d.body),
        pos: body_pos + d.offset,
        offset: d.offset,
        shape: d.shape.any(),
        mode: if d.solid {
            ColliderMode::Solid
        } else {
            ColliderMode::Trigger
        },
        layer: d.layer,
        mask: d.mask,
        one_way: d.one_way,
        tag: d.tag,
    }
}
