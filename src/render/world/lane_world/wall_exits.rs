//! Where held rays leave the room: `wall_exit` of every wall, asked of
//! only the wall of each opposite pair that a ray heads toward, and of the
//! other only where the ray might leave by it first.
//!
//! Why the other can be left out: a ray inside a wall's ball (anchor `a`,
//! outward normal `n`, radius `r`) that heads away from its anchor,
//! n · d < 0, leaves the ball by the far root, which is at least |b| with
//! b = (o − a) · d + r (n · d), so at least r |n · d| − |o − a|. Held
//! paths start in the room, which lies inside every wall's tangent plane;
//! with three pairs of opposite walls those planes bound a box-like cell
//! whose corners bound |o − a| (`reach`) and how far a ray goes before it
//! leaves by a wall it heads toward (`leave_within`). Where r |n · d| − |o − a|
//! exceeds that by a wide margin, the wall's exit (as `wall_exit` computes
//! it, in f32) is beyond the one the ray takes, and asking it would change
//! nothing. Six walls cost three exits a ray instead of six.

use glam::{DMat3, DVec3};

use crate::geometry::sphere::{wall_exit_along, AnchoredSphere};
use crate::render::world::lanes::{Index8, F8, LANES, M8, V8};

/// Opposite walls: normals at least this far from each other's (cosine).
const OPPOSITE: f64 = -0.9;

/// The walls a held path may leave by, as the lanes ask them.
#[derive(Clone, Debug, Default)]
pub(super) struct WallExits {
    /// Every wall, in index order: alone, or with the next when they face
    /// each other (asked in index order either way, so that ties go to the
    /// lower index as when every wall is asked).
    units: Vec<WallUnit>,
    /// The paired walls by slot (pair p's at 2p and 2p + 1), a row per
    /// field: anchor x, y, z, normal x, y, z, radius, shape index.
    slots: [[f32; LANES]; 8],
}

#[derive(Clone, Copy, Debug)]
enum WallUnit {
    Single(Wall),
    Pair(WallPair),
}

/// A wall and its shape index.
#[derive(Clone, Copy, Debug)]
struct Wall {
    sphere: AnchoredSphere,
    shape: f32,
}

#[derive(Clone, Copy, Debug)]
struct WallPair {
    /// The first wall's slot (the second's is the next).
    first: i32,
    walls: [Wall; 2],
    /// A ray with n · d below this for the wall it heads away from cannot
    /// leave by that wall first (module doc): −skip of the stricter wall.
    below: f32,
}

impl WallExits {
    /// `walls`: each wall with its shape index, in index order.
    pub(super) fn new(walls: &[(u32, AnchoredSphere)]) -> Self {
        let walls: Vec<Wall> = walls.iter().map(|&(shape, sphere)| Wall { sphere, shape: shape as f32 }).collect();
        let pairs = opposite_pairs(&walls);
        let bound = room_bound(&walls, &pairs);
        let mut exits = WallExits::default();
        let mut i = 0;
        while i < walls.len() {
            match bound.as_ref().filter(|_| pairs.contains(&i)) {
                Some(bound) => {
                    let slot = 2 * exits.pairs().count();
                    let pair = [walls[i], walls[i + 1]];
                    let below = -pair.map(|wall| bound.skip(&wall.sphere)).into_iter().fold(0.0, f64::max) as f32;
                    exits.units.push(WallUnit::Pair(WallPair { first: slot as i32, walls: pair, below }));
                    for (k, wall) in pair.iter().enumerate() {
                        let (a, n) = (wall.sphere.anchor, wall.sphere.normal);
                        let fields = [a.x, a.y, a.z, n.x, n.y, n.z, wall.sphere.radius, wall.shape];
                        for (row, value) in exits.slots.iter_mut().zip(fields) {
                            row[slot + k] = value;
                        }
                    }
                    i += 2;
                }
                None => {
                    exits.units.push(WallUnit::Single(walls[i]));
                    i += 1;
                }
            }
        }
        exits
    }

    fn pairs(&self) -> impl Iterator<Item = &WallPair> {
        self.units.iter().filter_map(|unit| match unit {
            WallUnit::Pair(pair) => Some(pair),
            WallUnit::Single(_) => None,
        })
    }

    /// How many walls a held ray asks at least.
    #[cfg(test)]
    pub(super) fn asked(&self) -> usize {
        self.units.len()
    }

    /// Where each `held` ray leaves by a wall before `t_hit`: `t_hit` and
    /// `index` (the shape) set there, as asking every wall in index order
    /// sets them.
    #[inline(always)]
    pub(super) fn leave(&self, held: M8, origin: V8, direction: V8, t_hit: &mut F8, index: &mut F8) {
        // Plain code: a closure here would not inherit AVX2
        for unit in &self.units {
            match unit {
                WallUnit::Single(wall) => {
                    let along = V8::splat(wall.sphere.normal).dot(direction);
                    ask(wall, along, held, origin, direction, t_hit, index);
                }
                WallUnit::Pair(pair) => {
                    let [first, second] = &pair.walls;
                    let along_first = V8::splat(first.sphere.normal).dot(direction);
                    let along_second = V8::splat(second.sphere.normal).dot(direction);
                    // Both where a ray might leave by the wall it turns from
                    let turned_far = along_first.min(along_second).lt(F8::splat(pair.below));
                    if held.and_not(turned_far).any() {
                        ask(first, along_first, held, origin, direction, t_hit, index);
                        ask(second, along_second, held, origin, direction, t_hit, index);
                        continue;
                    }
                    let slot = Index8::of_pair(pair.first, along_second.gt(along_first));
                    let [ax, ay, az, nx, ny, nz, radius, shape] = &self.slots;
                    let anchor = V8 { x: pick(ax, slot), y: pick(ay, slot), z: pick(az, slot) };
                    let normal = V8 { x: pick(nx, slot), y: pick(ny, slot), z: pick(nz, slot) };
                    // The chosen wall's n · d is the larger (equal ones differ at most
                    // in the sign of a zero, which b = e · d + r (n · d) and all
                    // that follows from it cannot tell)
                    let along = along_first.max(along_second);
                    let (t, exits) =
                        wall_exit_along(origin, direction, anchor, normal, along, pick(radius, slot), *t_hit);
                    keep(exits.and(held), t, pick(shape, slot), t_hit, index);
                }
            }
        }
    }
}

/// `wall_exit` of one wall for every lane, the rays' n · d (`along`) given.
#[inline(always)]
fn ask(wall: &Wall, along: F8, held: M8, origin: V8, direction: V8, t_hit: &mut F8, index: &mut F8) {
    let (anchor, normal) = (V8::splat(wall.sphere.anchor), V8::splat(wall.sphere.normal));
    let (t, exits) = wall_exit_along(origin, direction, anchor, normal, along, F8::splat(wall.sphere.radius), *t_hit);
    keep(exits.and(held), t, F8::splat(wall.shape), t_hit, index);
}

/// Each lane's slot's value of `row`.
#[inline(always)]
fn pick(row: &[f32; LANES], slot: Index8) -> F8 {
    F8::picked(F8::load(row), slot)
}

/// The lanes of `closer` take (t, shape).
#[inline(always)]
fn keep(closer: M8, t: F8, shape: F8, t_hit: &mut F8, index: &mut F8) {
    *t_hit = closer.select(t, *t_hit);
    *index = closer.select(shape, *index);
}

/// The first wall of each pair of consecutive walls (in index order) with
/// opposite normals, up to four pairs, none overlapping.
fn opposite_pairs(walls: &[Wall]) -> Vec<usize> {
    let mut pairs: Vec<usize> = Vec::new();
    let mut i = 0;
    while i + 1 < walls.len() && pairs.len() < LANES / 2 {
        let [a, b] = [i, i + 1].map(|k| walls[k].sphere.normal.as_dvec3());
        if a.dot(b) < OPPOSITE {
            pairs.push(i);
            i += 2;
        } else {
            i += 1;
        }
    }
    pairs
}

/// What bounds the room the walls' tangent planes close (module doc).
#[derive(Clone, Debug)]
struct RoomBound {
    /// The cell's corners.
    corners: Vec<DVec3>,
    /// Slack for points rounding puts outside the cell.
    slack: f64,
    /// A held ray leaves the room within this distance.
    leave_within: f64,
}

impl RoomBound {
    /// How far from `wall`'s anchor a held path may start.
    fn reach(&self, wall: &AnchoredSphere) -> f64 {
        let anchor = wall.anchor.as_dvec3();
        self.corners.iter().map(|c| c.distance(anchor)).fold(0.0, f64::max) + self.slack
    }

    /// The least |n · d| of a ray heading away from `wall` that leaves its
    /// ball only well after the room: r |n · d| (1 − 10⁻⁵) − reach (1 + 10⁻⁵)
    /// beyond the room's way out and a tenth more, the margins far above
    /// f32's rounding of b, of n · d and of the way out.
    fn skip(&self, wall: &AnchoredSphere) -> f64 {
        let beyond = 1.1 * self.leave_within + self.slack + self.reach(wall) * (1.0 + 1e-5);
        beyond / (wall.radius as f64 * (1.0 - 1e-5)) + 1e-6
    }
}

/// The cell the first three pairs' tangent planes close, if they close one:
/// their normals span space well enough that no direction escapes them.
fn room_bound(walls: &[Wall], pairs: &[usize]) -> Option<RoomBound> {
    let &[a, b, c, ..] = pairs else { return None };
    let pairs = [a, b, c].map(|i| [i, i + 1]);
    let normal = |i: usize| walls[i].sphere.normal.as_dvec3();
    // Each pair's first normal as the rows of `axes`: every unit d has
    // |axes d| ≥ 1/‖axes⁻¹‖, so |n · d| ≥ 1/(√3 ‖axes⁻¹‖) on one of them;
    // ‖axes⁻¹‖² is the largest eigenvalue of (axes axesᵀ)⁻¹, at most its
    // largest row sum of magnitudes (Gershgorin; near 1 for a box)
    let axes = DMat3::from_cols_array_2d(&pairs.map(|[a, _]| normal(a).to_array())).transpose();
    if axes.determinant().abs() < 1e-3 {
        return None;
    }
    let gram = (axes * axes.transpose()).inverse().to_cols_array_2d();
    let norm = gram.iter().map(|row| row.iter().map(|v| v.abs()).sum::<f64>()).fold(0.0, f64::max).sqrt();
    // Each pair's second normal is off the first's opposite by at most
    // `bent`, so a ray heads toward one wall with n · d ≥ `heading`; and
    // no direction leaves every tangent plane behind: the cell is bounded
    let bent = pairs.iter().map(|&[a, b]| (normal(a) + normal(b)).length()).fold(0.0, f64::max);
    let heading = 1.0 / (3f64.sqrt() * norm) - bent;
    if heading < 0.05 {
        return None;
    }
    // Its corners: three of the six tangent planes met, inside the others
    let planes: Vec<(DVec3, f64)> =
        pairs.iter().flatten().map(|&i| (normal(i), normal(i).dot(walls[i].sphere.anchor.as_dvec3()))).collect();
    let outside = |p: DVec3| planes.iter().map(|&(n, h)| n.dot(p) - h).fold(f64::NEG_INFINITY, f64::max);
    let mut corners = Vec::new();
    for i in 0..planes.len() {
        for j in i + 1..planes.len() {
            for k in j + 1..planes.len() {
                let rows = DMat3::from_cols(planes[i].0, planes[j].0, planes[k].0).transpose();
                if rows.determinant().abs() < 1e-9 {
                    continue;
                }
                let corner = rows.inverse() * DVec3::new(planes[i].1, planes[j].1, planes[k].1);
                if corner.is_finite() && outside(corner) <= 1e-9 * (1.0 + corner.abs().max_element()) {
                    corners.push(corner);
                }
            }
        }
    }
    if corners.len() < 4 {
        return None;
    }
    let size = corners.iter().map(|c| c.abs().max_element()).fold(0.0, f64::max);
    let slack = 1e-3 * (1.0 + size);
    // The ray leaves the ball of the wall it heads toward before that
    // wall's tangent plane, which is at most `gap` from the cell's points
    let gap = planes.iter().flat_map(|&(n, h)| corners.iter().map(move |c| h - n.dot(*c))).fold(0.0, f64::max);
    let leave_within = (gap + slack) / heading + slack;
    Some(RoomBound { corners, slack, leave_within })
}

#[cfg(test)]
mod tests {
    use glam::Vec3;

    use super::*;
    use crate::geometry::sphere::wall_exit;
    use crate::render::world::camera::CameraModel;
    use crate::render::world::lanes::supported;
    use crate::render::world::rng::Sampler;
    use crate::render::world::sampling::uniform_sphere;
    use crate::render::world::World;
    use crate::scene::{presets, Scene, Shape, ValidScene};

    fn world_of(scene: &Scene) -> World {
        let valid = ValidScene::new(scene.clone()).expect("a valid scene");
        World::for_view(&valid, &CameraModel::new(&scene.camera, 64, 48), 64, 48).0
    }

    fn walls_of(scene: &Scene) -> Vec<(u32, AnchoredSphere)> {
        world_of(scene).walls.wall_spheres
    }

    fn smallpt() -> Scene {
        presets::preset("smallpt").and_then(Result::ok).expect("smallpt").into_scene()
    }

    /// A room of six walls of radius 1e5 about (50, 40, 80), their pairs
    /// along three axes that are not square to each other.
    fn skewed_room() -> Scene {
        let mut scene = smallpt();
        let middle = Vec3::new(50.0, 40.0, 80.0);
        let axes = [Vec3::new(1.0, 0.2, 0.0), Vec3::new(0.3, 1.0, 0.1), Vec3::new(-0.1, 0.25, 1.0)];
        let half_widths = [50.0, 40.0, 80.0];
        let radius = 1e5f32;
        for (k, (axis, half_width)) in axes.iter().zip(half_widths).enumerate() {
            for (side, sign) in [(0, 1.0f32), (1, -1.0)] {
                let center = middle + axis.normalize() * ((radius - half_width) * sign);
                scene.objects[2 * k + side].shape = Shape::Sphere { center, radius };
            }
        }
        // The balls and the light away
        scene.objects.truncate(6);
        scene.camera.position = middle;
        scene.camera.look_at = middle + Vec3::Z;
        scene.camera.near_clip = 0.0;
        scene
    }

    /// Every wall asked in index order, as `LaneWorld::nearest` once did.
    fn every_wall(walls: &[(u32, AnchoredSphere)], held: M8, origin: V8, direction: V8) -> (F8, F8) {
        let (mut t_hit, mut index) = (F8::splat(f32::INFINITY), F8::splat(-1.0));
        for &(shape, sphere) in walls {
            let (anchor, normal, radius) =
                (V8::splat(sphere.anchor), V8::splat(sphere.normal), F8::splat(sphere.radius));
            let (t, exits) = wall_exit(origin, direction, anchor, normal, radius, t_hit);
            keep(exits.and(held), t, F8::splat(shape as f32), &mut t_hit, &mut index);
        }
        (t_hit, index)
    }

    #[test]
    fn smallpts_walls_pair_up_and_turn_from_few() {
        let exits = WallExits::new(&walls_of(&smallpt()));
        assert_eq!(exits.asked(), 3, "three pairs: {:?}", exits.units);
        for pair in exits.pairs() {
            // The room is ~200 across and the walls' radius 1e5: a ray must
            // turn from a wall by about 0.005 to leave it out
            assert!(-0.008 < pair.below && pair.below < 0.0, "{pair:?}");
        }
    }

    /// Walls whose neighbour in index order does not face them, or too few
    /// pairs to close a room, are each asked alone.
    #[test]
    fn walls_without_a_facing_neighbour_are_asked_alone() {
        let mut shuffled = smallpt();
        shuffled.objects.swap(1, 2);
        assert_eq!(WallExits::new(&walls_of(&shuffled)).asked(), 6);
        let mut open = smallpt();
        open.objects.truncate(4);
        let open_walls = walls_of(&open);
        assert_eq!((open_walls.len(), WallExits::new(&open_walls).asked()), (4, 4));
    }

    /// Held rays from all over smallpt's room and a skewed one, many near a
    /// wall and nearly along it, leave by the wall (and at the distance)
    /// that asking every wall in index order gives, bit for bit; among
    /// smallpt's, rays that leave by the wall they turn from, which a pair
    /// asks only when unsure.
    #[test]
    fn held_rays_leave_where_every_wall_says() {
        assert!(supported(), "the lanes need AVX2");
        let (low, high) = (Vec3::new(1.5, 0.5, 0.5), Vec3::new(98.5, 81.0, 169.5));
        let turned_from = leave_as_every_wall(&world_of(&smallpt()), low, high);
        assert!(turned_from > 20, "only {turned_from} rays left smallpt by a wall they turned from");
        let skewed = world_of(&skewed_room());
        assert_eq!(WallExits::new(&skewed.walls.wall_spheres).asked(), 3, "the skewed room's walls pair up");
        leave_as_every_wall(&skewed, Vec3::new(-60.0, -40.0, -60.0), Vec3::new(160.0, 120.0, 220.0));
    }

    /// `held_rays_leave_where_every_wall_says` on `world`'s walls, from
    /// origins in the box (`low`, `high`) inside every wall: how many rays
    /// left by a wall they turned from.
    fn leave_as_every_wall(world: &World, low: Vec3, high: Vec3) -> u32 {
        let walls = &world.walls.wall_spheres;
        let exits = WallExits::new(walls);
        let mut s = Sampler::new(3, 1, 4);
        let mut turned_from = 0;
        for round in 0..10_000 {
            let rays: [(Vec3, Vec3); LANES] = std::array::from_fn(|_| loop {
                let mut origin = low + (high - low) * Vec3::new(s.next_f32(), s.next_f32(), s.next_f32());
                let mut direction = uniform_sphere(s.next_2d());
                if round % 2 == 0 {
                    // Up to a unit inside a wall, heading along it, a little
                    // toward or away from its anchor
                    let (_, wall) = walls[(s.next_f32() * walls.len() as f32) as usize % walls.len()];
                    let depth = 0.01 + s.next_f32().powi(3) as f64;
                    let center = wall.anchor.as_dvec3() - wall.normal.as_dvec3() * wall.radius as f64;
                    let outward = (origin.as_dvec3() - center).normalize();
                    origin = (center + outward * (wall.radius as f64 - depth)).as_vec3();
                    let along = direction - wall.normal * direction.dot(wall.normal);
                    let lean = (s.next_f32() - 0.6) * 0.02 * s.next_f32().powi(4);
                    direction = (along.normalize_or(Vec3::X) + wall.normal * lean).normalize();
                }
                if world.walls.hold(origin) {
                    break (origin, direction);
                }
            });
            let origin = V8::from_fn(|i| rays[i].0);
            let direction = V8::from_fn(|i| rays[i].1);
            let held = M8::from_fn(|i| round % 7 != 0 || i % 3 != 0);
            let (mut t_hit, mut index) = (F8::splat(f32::INFINITY), F8::splat(-1.0));
            exits.leave(held, origin, direction, &mut t_hit, &mut index);
            let (t_all, index_all) = every_wall(walls, held, origin, direction);
            // What leaving a wall out rests on: each wall turned from by
            // more than its pair's bound is left only after the way out
            for pair in exits.pairs() {
                for wall in &pair.walls {
                    let along = V8::splat(wall.sphere.normal).dot(direction);
                    let (mut t, mut shape) = (F8::splat(f32::INFINITY), F8::splat(-1.0));
                    ask(wall, along, held, origin, direction, &mut t, &mut shape);
                    for i in along.lt(F8::splat(pair.below)).and(held).lanes() {
                        assert!(t.lane(i) > t_all.lane(i), "{:?} leaves {wall:?} at {}", rays[i], t.lane(i));
                    }
                }
            }
            for (i, ray) in rays.iter().enumerate() {
                let (got, want) =
                    ((t_hit.lane(i).to_bits(), index.lane(i)), (t_all.lane(i).to_bits(), index_all.lane(i)));
                assert_eq!(got, want, "ray {ray:?} held {}", held.test(i));
                let left_by = walls.iter().find(|(shape, _)| *shape as f32 == index_all.lane(i));
                turned_from += left_by.is_some_and(|(_, wall)| wall.normal.dot(ray.1) < 0.0) as u32;
            }
        }
        turned_from
    }
}
