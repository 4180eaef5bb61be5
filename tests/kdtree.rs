//! The kd-tree's k nearest, and the hash grid's points within a radius,
//! against a brute-force scan on random point sets, including the awkward
//! ones: duplicates, all points equal, k > n, n = 0 and 1, a radius that
//! excludes everything, points exactly on the radius, and the normal filter.

use gi_studio::render::integrators::photon_map::cells::PointGrid;
use gi_studio::render::integrators::photon_map::{Neighbours, Photon, PhotonKdTree};
use glam::Vec3;
use proptest::prelude::*;

fn photon(p: (f32, f32, f32), up: bool) -> Photon {
    Photon::new(Vec3::new(p.0, p.1, p.2), if up { Vec3::Y } else { -Vec3::Y }, [1.0, 0.5, 0.25])
}

/// Sorted squared distances of the k nearest by linear scan.
fn brute_force(photons: &[Photon], q: Vec3, normal: Option<Vec3>, k: usize, max_radius: f32) -> Vec<f32> {
    let mut d: Vec<f32> = photons
        .iter()
        .filter(|p| normal.is_none_or(|n| p.incoming_direction().dot(n) < 0.0))
        .map(|p| (p.position - q).length_squared())
        .filter(|d2| *d2 <= max_radius * max_radius)
        .collect();
    d.sort_by(f32::total_cmp);
    d.truncate(k);
    d
}

fn tree_result(tree: &PhotonKdTree, q: Vec3, normal: Option<Vec3>, k: usize, max_radius: f32) -> Vec<f32> {
    let mut out = Neighbours::new(k);
    let visited = tree.k_nearest(q, normal, k, max_radius, &mut out);
    // The walk (the nodes-visited statistic) starts at the root and meets
    // every neighbour it keeps
    assert_eq!(visited > 0, k > 0 && !tree.is_empty() && max_radius >= 0.0);
    assert!(visited >= out.len());
    assert_eq!(out.is_empty(), out.as_slice().is_empty());
    let photons = tree.photons();
    let mut d: Vec<f32> = out
        .as_slice()
        .iter()
        .map(|&(d2, i)| {
            // The reported distance is the photon's own
            assert_eq!(d2, (photons[i as usize].position - q).length_squared());
            d2
        })
        .collect();
    d.sort_by(f32::total_cmp);
    d
}

/// Sorted squared distances of the grid's points within `radius`, in cells
/// `cell` wide; each point at most once.
fn grid_result(photons: &[Photon], cell: f32, q: Vec3, radius: f32) -> Vec<f32> {
    let grid = PointGrid::build(photons, |p| p.position, cell);
    let mut indices = Vec::new();
    grid.for_each_within(q, radius, |i| indices.push(i));
    let mut unique = indices.clone();
    unique.sort_unstable();
    unique.dedup();
    assert_eq!(unique.len(), indices.len(), "a point found twice");
    let mut d: Vec<f32> = indices.iter().map(|&i| (photons[i as usize].position - q).length_squared()).collect();
    d.sort_by(f32::total_cmp);
    d
}

fn coordinate() -> impl Strategy<Value = f32> {
    // A coarse grid makes duplicates and ties common
    prop_oneof![(-8i32..8).prop_map(|v| v as f32 * 0.25), -2.0f32..2.0]
}

fn points() -> impl Strategy<Value = Vec<((f32, f32, f32), bool)>> {
    prop::collection::vec(((coordinate(), coordinate(), coordinate()), any::<bool>()), 0..300)
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(200))]

    #[test]
    fn k_nearest_equals_brute_force(
        points in points(),
        q in (coordinate(), coordinate(), coordinate()),
        k in 0usize..40,
        max_radius in prop_oneof![Just(f32::INFINITY), Just(0.0f32), 0.0f32..3.0],
        filter in any::<bool>(),
    ) {
        let photons: Vec<Photon> = points.iter().map(|(p, up)| photon(*p, *up)).collect();
        let tree = PhotonKdTree::build(photons.clone());
        let q = Vec3::new(q.0, q.1, q.2);
        let normal = filter.then_some(Vec3::Y);
        prop_assert_eq!(tree_result(&tree, q, normal, k, max_radius), brute_force(&photons, q, normal, k, max_radius));
    }

    #[test]
    fn grid_within_radius_equals_brute_force(
        points in points(),
        q in (coordinate(), coordinate(), coordinate()),
        radius in 0.0f32..2.0,
        cells in prop_oneof![Just(1.0f32), Just(4.0), 0.1f32..8.0],
    ) {
        let photons: Vec<Photon> = points.iter().map(|(p, up)| photon(*p, *up)).collect();
        let q = Vec3::new(q.0, q.1, q.2);
        prop_assert_eq!(grid_result(&photons, radius * cells, q, radius), brute_force(&photons, q, None, usize::MAX, radius));
    }
}

#[test]
fn degenerate_sets() {
    let q = Vec3::new(0.1, 0.2, 0.3);
    // n = 0
    let empty = PhotonKdTree::build(Vec::new());
    assert!(empty.is_empty());
    assert_eq!((empty.len(), empty.depth()), (0, 0));
    assert!(tree_result(&empty, q, None, 5, f32::INFINITY).is_empty());
    // n = 1, k > n
    let one = PhotonKdTree::build(vec![photon((1.0, 1.0, 1.0), true)]);
    assert!(!one.is_empty());
    assert_eq!((one.len(), one.depth()), (1, 1));
    assert_eq!(tree_result(&one, q, None, 5, f32::INFINITY).len(), 1);
    // All photons at one point: k of them at the same distance
    let same: Vec<Photon> = (0..1000).map(|_| photon((0.5, 0.5, 0.5), false)).collect();
    let tree = PhotonKdTree::build(same);
    let found = tree_result(&tree, Vec3::splat(0.5), None, 50, 1.0);
    assert_eq!(found, vec![0.0; 50]);
    // A radius that excludes everything
    assert!(tree_result(&tree, Vec3::splat(5.0), None, 50, 1.0).is_empty());
    // A negative radius holds nothing, not what its square would
    assert!(tree_result(&tree, Vec3::splat(0.5), None, 50, -1.0).is_empty());
    let same: Vec<Photon> = (0..1000).map(|_| photon((0.5, 0.5, 0.5), false)).collect();
    assert!(grid_result(&same, 1.0, Vec3::splat(0.5), -1.0).is_empty());
    // A radius of 0 holds the photons exactly there (distance ≤ radius)
    assert_eq!(grid_result(&same, 1.0, Vec3::splat(0.5), 0.0), vec![0.0; 1000]);
    assert_eq!(grid_result(&same, 0.0, Vec3::splat(0.5), 0.0), vec![0.0; 1000]);
    assert!(grid_result(&[], 1.0, q, 1.0).is_empty());
    assert_eq!(tree_result(&tree, Vec3::splat(0.5), None, 50, 0.0), vec![0.0; 50]);
    // Photons from behind the surface are skipped: all travel down (-y), so a
    // surface facing down sees none of them
    assert!(tree_result(&tree, Vec3::splat(0.5), Some(-Vec3::Y), 50, 1.0).is_empty());
    assert_eq!(tree_result(&tree, Vec3::splat(0.5), Some(Vec3::Y), 50, 1.0).len(), 50);
}

/// Photons on a whole grid, gathered at every grid point with radii that are
/// grid distances: neighbours lie exactly on the bound, and many of them on
/// a split plane, in a subtree deferred at exactly the bound's distance, and
/// on the edges of the grid's cells. A photon on the bound is in (≤), as in
/// the brute-force scan.
#[test]
fn photons_exactly_at_the_gather_radius_are_found() {
    let grid = |n: i32| (0..n).flat_map(move |x| (0..n).flat_map(move |y| (0..n).map(move |z| (x, y, z))));
    let photons: Vec<Photon> = grid(5).map(|(x, y, z)| photon((x as f32, y as f32, z as f32), false)).collect();
    let tree = PhotonKdTree::build(photons.clone());
    for (x, y, z) in grid(5) {
        let q = Vec3::new(x as f32, y as f32, z as f32);
        for radius in [1.0, 2.0_f32.sqrt(), 2.0] {
            // k above what the radius holds: the bound stays the radius
            assert_eq!(
                tree_result(&tree, q, None, 60, radius),
                brute_force(&photons, q, None, 60, radius),
                "at {q}, r {radius}"
            );
            // Cells exactly the radius (SPPM's) and four radii (VCM's)
            for cells in [1.0, 4.0] {
                let within = brute_force(&photons, q, None, usize::MAX, radius);
                assert_eq!(grid_result(&photons, radius * cells, q, radius), within, "at {q}, r {radius}");
            }
        }
    }
}
