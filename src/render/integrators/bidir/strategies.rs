//! What each strategy brings to the image: the light of paths of k
//! segments made with s vertices from the light (s = 0: the camera path
//! met the light; s = 1: next-event estimation; s = k: a light path joined
//! to the camera; between: a connection) or merged at the camera subpath's
//! c-th vertex, weighted by multiple importance sampling and not. Kept at a
//! quarter of the pane's size per side, for paths up to `MAX_LENGTH`
//! segments, when the studio's strategy view asks (pbrt-v4 writes such
//! images when a render ends; here they refine with the pane).

use std::sync::Arc;

use crate::scene::Rgb;

/// Paths up to this many segments are shown.
pub const MAX_LENGTH: u32 = 5;
/// Strategy images are this many times smaller than the pane, per side.
pub const SHRINK: u32 = 4;

/// A way of making a path.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Strategy {
    /// `light_vertices` from the light, the rest from the camera, connected.
    Connect { length: u32, light_vertices: u32 },
    /// Merged at the camera subpath's `camera_vertex`-th vertex.
    Merge { length: u32, camera_vertex: u32 },
}

impl Strategy {
    pub fn length(&self) -> u32 {
        match *self {
            Strategy::Connect { length, .. } | Strategy::Merge { length, .. } => length,
        }
    }

    /// Every strategy shown, in the view's order: by length, connections
    /// (s = 0…k) then merges (c = 1…k−1).
    pub fn all() -> Vec<Strategy> {
        let mut all = Vec::new();
        for length in 1..=MAX_LENGTH {
            all.extend((0..=length).map(|light_vertices| Strategy::Connect { length, light_vertices }));
            all.extend((1..length).map(|camera_vertex| Strategy::Merge { length, camera_vertex }));
        }
        all
    }

    /// Its place in `all`, if shown.
    pub fn index(&self) -> Option<usize> {
        let length = self.length();
        if length == 0 || length > MAX_LENGTH {
            return None;
        }
        // Lengths before this one: k + 1 connections and k − 1 merges each
        let before: u32 = (1..length).map(|k| 2 * k).sum();
        let within = match *self {
            Strategy::Connect { light_vertices, .. } if light_vertices <= length => light_vertices,
            Strategy::Merge { camera_vertex, .. } if camera_vertex >= 1 && camera_vertex < length => {
                length + camera_vertex
            }
            _ => return None,
        };
        Some((before + within) as usize)
    }

    /// As a user reads it: "(s, t) = (1, 2)" or "merged at camera vertex 1".
    pub fn label(&self) -> String {
        match *self {
            Strategy::Connect { length, light_vertices } => {
                format!("(s, t) = ({light_vertices}, {})", length + 1 - light_vertices)
            }
            Strategy::Merge { camera_vertex, .. } => format!("merged at camera vertex {camera_vertex}"),
        }
    }
}

/// One contribution: to which small pixel, by which strategy, weighted and
/// its weight.
#[derive(Clone, Copy, Debug)]
pub struct Contribution {
    pub cell: u32,
    pub pixel: u32,
    pub weighted: Rgb,
    pub weight: f32,
}

/// Where a pass's contributions go (the strategy view), or nowhere.
pub trait Tally {
    fn add(&mut self, strategy: Strategy, weighted: Rgb, weight: f32);
}

/// Counts nothing: a render without the view pays nothing.
pub struct NoTally;

impl Tally for NoTally {
    #[inline(always)]
    fn add(&mut self, _: Strategy, _: Rgb, _: f32) {}
}

/// The contributions of one pixel's (or one light path's) strategies.
pub struct PixelTally<'a> {
    pub pixel: u32,
    pub out: &'a mut Vec<Contribution>,
}

impl PixelTally<'_> {
    /// What `add` keeps: a shown strategy's part that brought light.
    pub fn contribution(pixel: u32, strategy: Strategy, weighted: Rgb, weight: f32) -> Option<Contribution> {
        let cell = strategy.index()?;
        (weighted != Rgb::ZERO && weight > 0.0).then_some(Contribution { cell: cell as u32, pixel, weighted, weight })
    }
}

impl Tally for PixelTally<'_> {
    fn add(&mut self, strategy: Strategy, weighted: Rgb, weight: f32) {
        self.out.extend(Self::contribution(self.pixel, strategy, weighted, weight));
    }
}

/// The small images of every strategy, as sums over the passes so far.
#[derive(Clone, Debug)]
pub struct StrategyFilm {
    pub width: u32,
    pub height: u32,
    pub passes: u32,
    /// Per strategy (`Strategy::all` order), weighted and not, per small pixel.
    pub weighted: Vec<Vec<[f64; 3]>>,
    pub unweighted: Vec<Vec<[f64; 3]>>,
}

impl StrategyFilm {
    /// For a pane of `width × height`.
    pub fn new(width: u32, height: u32) -> Self {
        let (w, h) = (width.div_ceil(SHRINK), height.div_ceil(SHRINK));
        let cells = Strategy::all().len();
        let empty = vec![vec![[0.0; 3]; (w * h) as usize]; cells];
        StrategyFilm { width: w, height: h, passes: 0, weighted: empty.clone(), unweighted: empty }
    }

    /// The small pixel of pane pixel (x, y).
    #[inline]
    pub fn pixel(&self, x: u32, y: u32) -> u32 {
        (y / SHRINK) * self.width + x / SHRINK
    }

    /// Add contributions (in the order the work was numbered). Each lands
    /// on its small pixel, which stands for SHRINK² pane pixels: the sums
    /// are divided by them when shown.
    pub fn add(&mut self, contributions: &[Contribution]) {
        for c in contributions {
            let (weighted, unweighted) = (&mut self.weighted[c.cell as usize], &mut self.unweighted[c.cell as usize]);
            for k in 0..3 {
                weighted[c.pixel as usize][k] += c.weighted[k] as f64;
                unweighted[c.pixel as usize][k] += (c.weighted[k] / c.weight) as f64;
            }
        }
    }

    /// What the view shows now: each strategy's mean small images.
    pub fn images(&self) -> StrategyImages {
        let scale = 1.0 / (self.passes.max(1) as f64 * (SHRINK * SHRINK) as f64);
        let mean = |sums: &Vec<[f64; 3]>| sums.iter().map(|s| s.map(|c| (c * scale) as f32)).collect();
        let brought_light = self.unweighted.iter().map(|sums| sums.iter().any(|s| s.iter().any(|&c| c != 0.0)));
        StrategyImages {
            brought_light: brought_light.collect(),
            width: self.width,
            height: self.height,
            passes: self.passes,
            strategies: Strategy::all(),
            weighted: self.weighted.iter().map(mean).collect(),
            unweighted: self.unweighted.iter().map(mean).collect(),
        }
    }
}

/// Every strategy's small images after some passes, for the view.
#[derive(Clone, Debug)]
pub struct StrategyImages {
    pub width: u32,
    pub height: u32,
    pub passes: u32,
    pub strategies: Vec<Strategy>,
    /// Whether each strategy has brought any light yet: those the method
    /// does not use (merges in BDPT, the light seen from its own first
    /// vertex) never do.
    pub brought_light: Vec<bool>,
    pub weighted: Vec<Vec<[f32; 3]>>,
    pub unweighted: Vec<Vec<[f32; 3]>>,
}

/// How often the view is refreshed: after each of the first eight passes,
/// then every eighth (each costs a copy of every strategy's image).
pub fn due(pass: u32) -> bool {
    pass < 8 || (pass + 1) % 8 == 0
}

pub type SharedImages = Arc<StrategyImages>;

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_strategy_has_its_own_place() {
        let all = Strategy::all();
        for (i, strategy) in all.iter().enumerate() {
            assert_eq!(strategy.index(), Some(i), "{strategy:?}");
        }
        assert_eq!(all.len(), (1..=MAX_LENGTH).map(|k| 2 * k as usize).sum::<usize>());
        assert_eq!(Strategy::Connect { length: MAX_LENGTH + 1, light_vertices: 0 }.index(), None);
        assert_eq!(Strategy::Merge { length: 3, camera_vertex: 3 }.index(), None);
        assert_eq!(Strategy::Connect { length: 2, light_vertices: 1 }.label(), "(s, t) = (1, 2)");
    }

    /// A contribution lands on its strategy's small pixel, weighted and
    /// divided by its weight, averaged over passes and the SHRINK² pane
    /// pixels it stands for; only strategies that received light say so.
    #[test]
    fn contributions_land_on_their_strategy_and_pixel() {
        let mut film = StrategyFilm::new(2 * SHRINK, SHRINK);
        let strategy = Strategy::Connect { length: 3, light_vertices: 2 };
        let mut out = Vec::new();
        let mut tally = PixelTally { pixel: film.pixel(SHRINK, 0), out: &mut out };
        tally.add(strategy, Rgb::new(0.5, 1.0, 2.0), 0.25);
        tally.add(Strategy::Merge { length: 2, camera_vertex: 1 }, Rgb::ZERO, 0.5);
        film.add(&out);
        film.passes = 2;
        let images = film.images();
        let cell = strategy.index().unwrap();
        let scale = 1.0 / (2.0 * (SHRINK * SHRINK) as f32);
        assert_eq!(images.weighted[cell], vec![[0.0; 3], [0.5 * scale, scale, 2.0 * scale]]);
        assert_eq!(images.unweighted[cell][1], [2.0 * scale, 4.0 * scale, 8.0 * scale]);
        let lit: Vec<usize> = (0..images.strategies.len()).filter(|&i| images.brought_light[i]).collect();
        assert_eq!(lit, vec![cell]);
    }
}
