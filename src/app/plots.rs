//! Plots of every pane: time per pass, samples per second over time, error
//! against time on log–log axes, and the photon maps' statistics.

use eframe::egui;
use egui_plot::{Bar, BarChart, Corner, HLine, Legend, Line, LineStyle, Plot};

use super::pane::{Pane, PaneError};
use crate::render::integrators::photon_map::maps::RADIUS_BINS;
use crate::render::integrators::SppmTimes;

/// The plots in a panel `panel_height` high.
pub fn plots_ui(ui: &mut egui::Ui, panes: &[Pane], panel_height: f32) {
    // Room for the titles above the plots (two lines, where they wrap)
    let height = (panel_height - 2.5 * ui.text_style_height(&egui::TextStyle::Body)).max(60.0);
    ui.columns(4, |columns| {
        columns[0].label("Time per pass (ms)");
        Plot::new("pass_time").legend(Legend::default()).height(height).show(&mut columns[0], |plot| {
            for (i, pane) in panes.iter().enumerate() {
                let points: Vec<[f64; 2]> =
                    pane.state().history.iter().map(|r| [r.passes as f64, r.pass_seconds * 1e3]).collect();
                plot.line(pane_line(i, pane, points));
            }
        });
        columns[1].label("Samples per second (M) over time (s)");
        Plot::new("throughput").legend(Legend::default()).height(height).show(&mut columns[1], |plot| {
            for (i, pane) in panes.iter().enumerate() {
                let points: Vec<[f64; 2]> =
                    pane.state().history.iter().map(|r| [r.seconds, r.samples_per_second / 1e6]).collect();
                plot.line(pane_line(i, pane, points));
            }
        });
        columns[2].label("log₁₀ relMSE against log₁₀ seconds (dashed: estimated from own noise)");
        // Errors fall as time goes on: the lower left is where no curve is
        let legend = Legend::default().position(Corner::LeftBottom);
        Plot::new("error").legend(legend).height(height).show(&mut columns[2], |plot| {
            let mut floor = None;
            for (i, pane) in panes.iter().enumerate() {
                let (mut line, mut low, mut high, mut estimated) = (Vec::new(), Vec::new(), Vec::new(), false);
                for record in &pane.state().history {
                    // A bound is not a figure to draw
                    let drawn = |e: &PaneError| e.rel_mse() > 0.0 && !matches!(e, PaneError::Below(_));
                    let Some(error) = record.error.filter(drawn) else { continue };
                    let t = record.seconds.max(1e-6).log10();
                    line.push([t, error.rel_mse().log10()]);
                    // ±1 standard error, where it stays above zero
                    let spread = error.standard_error();
                    low.push([t, (error.rel_mse() - spread).max(error.rel_mse() * 0.1).log10()]);
                    high.push([t, (error.rel_mse() + spread).log10()]);
                    match error {
                        PaneError::Measured(e) => floor = e.noise_floor.or(floor),
                        PaneError::Estimated(_) | PaneError::Below(_) => estimated = true,
                    }
                }
                let style = if estimated { LineStyle::dashed_loose() } else { LineStyle::Solid };
                plot.line(pane_line(i, pane, line).style(style));
                plot.line(pane_line(i, pane, low).width(0.5));
                plot.line(pane_line(i, pane, high).width(0.5));
            }
            if let Some(floor) = floor.filter(|f| *f > 0.0) {
                let line = HLine::new("reference's own noise", floor.log10()).color(NOISE_FLOOR_COLOR);
                plot.hline(line.style(LineStyle::dotted_dense()));
            }
        });
        photons_and_paths_ui(&mut columns[3], panes, height);
    });
}

/// Pane `index`'s line through `points`, named and coloured as the pane in
/// every plot: a pane's several lines (the error and its ±1 standard
/// error) share its colour, and the legend shows it.
fn pane_line(index: usize, pane: &Pane, points: Vec<[f64; 2]>) -> Line<'static> {
    let name = format!("{} {}", index + 1, pane.algorithm().name());
    Line::new(name, points).color(pane_color(index))
}

/// Grey: no pane's colour.
const NOISE_FLOOR_COLOR: egui::Color32 = egui::Color32::GRAY;

/// egui_plot's own sequence of colours (what it gives the `index`th line
/// left to choose), so panes keep the colours they had.
fn pane_color(index: usize) -> egui::Color32 {
    let golden_ratio = (5.0_f32.sqrt() - 1.0) / 2.0;
    egui::ecolor::Hsva::new(index as f32 * golden_ratio, 0.85, 0.5, 1.0).into()
}

fn photons_and_paths_ui(ui: &mut egui::Ui, panes: &[Pane], height: f32) {
    ui.label("Photon maps and light paths");
    let mut any = false;
    for (i, pane) in panes.iter().enumerate() {
        if let Some(maps) = &pane.state().maps {
            any = true;
            for (name, map) in [("global", &maps.global), ("caustic", &maps.caustic)] {
                ui.small(format!(
                    "{}: {name}: {} stored of {} · {:.1} MB · build {:.0} ms · depth {}",
                    i + 1,
                    map.stored,
                    map.emitted,
                    map.bytes as f64 / 1e6,
                    map.build_time.as_secs_f64() * 1e3,
                    map.depth
                ));
            }
        }
        if let Some(stats) = &pane.state().stats {
            let q = &stats.photon.queries;
            if q.queries > 0 {
                any = true;
                ui.small(format!(
                    "{}: k-NN {:.0} nodes, {:.2} µs per query{}",
                    i + 1,
                    q.mean_nodes_visited(),
                    q.mean_query_time().as_secs_f64() * 1e6,
                    if stats.photon.mean_radius > 0.0 {
                        format!(" · SPPM radius {:.4}", stats.photon.mean_radius)
                    } else {
                        String::new()
                    }
                ));
                let bars: Vec<Bar> = q
                    .radius_histogram
                    .iter()
                    .enumerate()
                    .map(|(b, n)| {
                        Bar::new((b as f64 + 0.5) / RADIUS_BINS as f64, *n as f64).width(0.9 / RADIUS_BINS as f64)
                    })
                    .collect();
                Plot::new(("radii", i)).height(height * 0.5).show(ui, |plot| {
                    plot.bar_chart(BarChart::new("gather radius / max", bars));
                });
            }
        }
    }
    let radii: Vec<(usize, Vec<[f64; 2]>)> = panes
        .iter()
        .enumerate()
        .map(|(i, pane)| {
            (
                i,
                pane.state()
                    .history
                    .iter()
                    .filter_map(|r| r.sppm_radius.map(|radius| [r.passes as f64, radius as f64]))
                    .collect::<Vec<_>>(),
            )
        })
        .filter(|(_, points)| !points.is_empty())
        .collect();
    if !radii.is_empty() {
        any = true;
        ui.small("SPPM mean radius per pass");
        Plot::new("sppm_radius").height(height * 0.5).show(ui, |plot| {
            for (i, points) in radii {
                plot.line(pane_line(i, &panes[i], points));
            }
        });
    }
    for (i, pane) in panes.iter().enumerate() {
        let Some(stats) = &pane.state().stats else { continue };
        if stats.photon.photons_traced > 0 {
            any = true;
            sppm_times_ui(ui, i, &stats.photon.times, height);
        }
    }
    for (i, pane) in panes.iter().enumerate() {
        let Some(stats) = &pane.state().stats else { continue };
        let p = &stats.paths;
        if p.light_paths > 0 {
            any = true;
            let per = |n: u64| n as f64 / p.light_paths as f64;
            let radius =
                if p.merge_radius > 0.0 { format!(" · merge radius {:.4}", p.merge_radius) } else { String::new() };
            ui.small(format!(
                "{}: {:.2} light vertices a path · per pixel {:.2} connections, {:.2} merges{radius}",
                i + 1,
                per(p.light_vertices),
                per(p.connections),
                per(p.merges)
            ));
        }
    }
    if !any {
        ui.weak("Statistics appear when a pane renders with photon mapping, SPPM or a bidirectional method.");
    }
}

/// Where pane `index`'s last SPPM pass spent its time: a line of figures
/// and a bar a stage.
fn sppm_times_ui(ui: &mut egui::Ui, index: usize, times: &SppmTimes, height: f32) {
    ui.small(format!("{}: SPPM last pass: {}", index + 1, times.summary()));
    Plot::new(("sppm_times", index)).legend(Legend::default()).height(height * 0.5).show(ui, |plot| {
        for (x, (stage, time)) in times.stages().iter().enumerate() {
            let bar = Bar::new(x as f64, time.as_secs_f64() * 1e3).width(0.8);
            plot.bar_chart(BarChart::new(*stage, vec![bar]));
        }
    });
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn four_panes_have_four_colours_none_of_them_the_noise_floors() {
        let colours: Vec<_> = (0..4).map(pane_color).collect();
        for (i, a) in colours.iter().enumerate() {
            assert_ne!(*a, NOISE_FLOOR_COLOR);
            for b in &colours[i + 1..] {
                let distance: i32 = (0..3).map(|c| (a[c] as i32 - b[c] as i32).abs()).sum();
                assert!(distance > 60, "panes' colours {a:?} and {b:?} are too close to tell apart");
            }
        }
    }
}
