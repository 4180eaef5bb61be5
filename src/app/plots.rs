//! Plots of every pane: time per pass, samples per second over time, error
//! against time on log–log axes, and the photon maps' statistics.

use eframe::egui;
use egui_plot::{Bar, BarChart, HLine, Legend, Line, LineStyle, Plot};

use super::pane::{Pane, PaneError};
use crate::render::integrators::photon_map::maps::RADIUS_BINS;
use crate::render::integrators::SppmTimes;

pub fn plots_ui(ui: &mut egui::Ui, panes: &[Pane]) {
    // A fixed height: plots asking for all the space would push the panes out
    let height = 150.0;
    ui.columns(4, |columns| {
        columns[0].label("Time per pass (ms)");
        Plot::new("pass_time").legend(Legend::default()).height(height).show(&mut columns[0], |plot| {
            for (i, pane) in panes.iter().enumerate() {
                let points: Vec<[f64; 2]> =
                    pane.state().history.iter().map(|r| [r.passes as f64, r.pass_seconds * 1e3]).collect();
                plot.line(Line::new(series_name(i, pane), points));
            }
        });
        columns[1].label("Samples per second (M) over time (s)");
        Plot::new("throughput").legend(Legend::default()).height(height).show(&mut columns[1], |plot| {
            for (i, pane) in panes.iter().enumerate() {
                let points: Vec<[f64; 2]> =
                    pane.state().history.iter().map(|r| [r.seconds, r.samples_per_second / 1e6]).collect();
                plot.line(Line::new(series_name(i, pane), points));
            }
        });
        columns[2].label("log₁₀ relMSE against log₁₀ seconds (dashed: estimated from own noise)");
        Plot::new("error").legend(Legend::default()).height(height).show(&mut columns[2], |plot| {
            let mut floor = None;
            for (i, pane) in panes.iter().enumerate() {
                let (mut line, mut low, mut high, mut estimated) = (Vec::new(), Vec::new(), Vec::new(), false);
                for record in &pane.state().history {
                    let Some(error) = record.error.filter(|e| e.rel_mse() > 0.0) else { continue };
                    let t = record.seconds.max(1e-6).log10();
                    line.push([t, error.rel_mse().log10()]);
                    // ±1 standard error, where it stays above zero
                    let spread = error.standard_error();
                    low.push([t, (error.rel_mse() - spread).max(error.rel_mse() * 0.1).log10()]);
                    high.push([t, (error.rel_mse() + spread).log10()]);
                    match error {
                        PaneError::Measured(e) => floor = e.noise_floor.or(floor),
                        PaneError::Estimated(_) => estimated = true,
                    }
                }
                let name = series_name(i, pane);
                let style = if estimated { LineStyle::dashed_loose() } else { LineStyle::Solid };
                plot.line(Line::new(name.clone(), line).style(style));
                plot.line(Line::new(name.clone(), low).width(0.5));
                plot.line(Line::new(name, high).width(0.5));
            }
            if let Some(floor) = floor.filter(|f| *f > 0.0) {
                plot.hline(HLine::new("reference's own noise", floor.log10()).style(LineStyle::dotted_dense()));
            }
        });
        photons_and_paths_ui(&mut columns[3], panes, height);
    });
}

fn series_name(index: usize, pane: &Pane) -> String {
    format!("{} {}", index + 1, pane.algorithm().name())
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
                plot.line(Line::new(series_name(i, &panes[i]), points));
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
