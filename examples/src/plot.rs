//! SVG line plots for the examples: vertically stacked panels that share one x axis.
//!
//! The examples plot quantities with different units against the same abscissa (e.g. piston position,
//! velocity and acceleration against crank angle), so each quantity gets its own panel with its own y
//! axis and all panels share the x range. Rendering uses plotters' SVG backend without font support:
//! text is emitted as SVG `<text>` elements and laid out by the viewer, so no font files are needed.
//!
//! Data are never trusted: non-finite points are skipped (a line is broken at them rather than joined
//! across the gap), empty series and empty panel lists still produce a valid SVG, and degenerate ranges
//! are widened so that nothing divides by zero.

use core::fmt;
use core::ops::Range;
use std::path::Path;

use plotters::coord::Shift;
use plotters::prelude::*;

/// One named curve of a [`Panel`].
#[derive(Debug, Clone, Copy)]
pub struct Series<'a> {
    /// Legend entry; empty names get no legend entry.
    pub name: &'a str,
    /// The curve's points `(x, y)`, drawn in order. Non-finite points are skipped (the line breaks there).
    pub points: &'a [(f64, f64)],
}

/// One plot panel: a y axis (with its label, including units) and the curves drawn against it.
#[derive(Debug, Clone, Copy)]
pub struct Panel<'a> {
    /// Y axis label, with units, e.g. `"position (mm)"`.
    pub y_label: &'a str,
    /// Curves drawn in this panel, in legend order.
    pub series: &'a [Series<'a>],
}

/// Why a plot could not be written.
#[derive(Debug)]
pub enum PlotError {
    /// The plotting backend failed while drawing.
    Draw(String),
    /// The directory the SVG file would go in does not exist (it is not created: a typo in a
    /// path should not leave new directories behind).
    MissingDirectory(std::path::PathBuf),
    /// Writing the SVG file failed.
    Io(std::io::Error),
}

impl fmt::Display for PlotError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            PlotError::Draw(msg) => write!(f, "plot drawing failed: {msg}"),
            PlotError::MissingDirectory(dir) => write!(
                f,
                "the directory `{}` does not exist: create it, or give a path in an existing \
                 directory",
                dir.display()
            ),
            PlotError::Io(e) => write!(f, "writing plot failed: {e}"),
        }
    }
}

impl std::error::Error for PlotError {
    fn source(&self) -> Option<&(dyn std::error::Error + 'static)> {
        match self {
            PlotError::Draw(_) | PlotError::MissingDirectory(_) => None,
            PlotError::Io(e) => Some(e),
        }
    }
}

impl From<std::io::Error> for PlotError {
    fn from(e: std::io::Error) -> Self {
        PlotError::Io(e)
    }
}

/// plotters' error types are generic over the backend; keep only the message.
fn draw_err<E: fmt::Debug>(e: E) -> PlotError {
    PlotError::Draw(format!("{e:?}"))
}

/// Figure width, px.
const WIDTH: u32 = 900;
/// Height reserved for the title, px.
const TITLE_H: u32 = 46;
/// Height of each panel's plotting band (plot area plus a small gap), px.
const PANEL_H: u32 = 258;
/// Extra height under the bottom panel for the x tick labels and the x axis label, px.
const X_AXIS_H: u32 = 56;
/// Outer margin, px.
const MARGIN: u32 = 12;
/// Width of the y label area; fixed so the plot areas of all panels line up, px.
const Y_AXIS_W: u32 = 96;
/// Internal supersampling factor. plotters rounds every coordinate to an integer pixel, which makes
/// curves visibly jagged at 900 px; drawing at twice the size and declaring the nominal size on the
/// `<svg>` element (the `viewBox` keeps the doubled coordinates) halves that quantisation.
pub(crate) const RES: u32 = 2;

/// A nominal length (px or font size) in internal drawing units.
pub(crate) const fn px(v: u32) -> i32 {
    (v * RES) as i32
}

/// Colour-blind-friendly categorical palette (Tableau 10 order), so multi-series panels stay readable.
pub(crate) const PALETTE: [RGBColor; 6] = [
    RGBColor(31, 119, 180),
    RGBColor(214, 39, 40),
    RGBColor(44, 160, 44),
    RGBColor(255, 127, 14),
    RGBColor(148, 103, 189),
    RGBColor(140, 86, 75),
];

/// Figure size in pixels for `n_panels` stacked panels (900 × 900 for three).
pub fn figure_size(n_panels: usize) -> (u32, u32) {
    let n = u32::try_from(n_panels).unwrap_or(u32::MAX).min(64);
    (WIDTH, 2 * MARGIN + TITLE_H + n * PANEL_H + X_AXIS_H)
}

/// Renders the panels as an SVG document and writes it to `path`.
///
/// `title` goes on top, `x_label` (with units) under the bottom panel; all panels share the x range
/// of all finite points.
///
/// # Errors
/// [`PlotError::MissingDirectory`] naming the first directory of `path` that does not exist
/// (none is created), a drawing or a write failure.
pub fn write_svg(
    path: &Path,
    title: &str,
    x_label: &str,
    panels: &[Panel<'_>],
) -> Result<(), PlotError> {
    if let Some(missing) = missing_directory(path) {
        return Err(PlotError::MissingDirectory(missing));
    }
    let svg = render_svg(title, x_label, panels)?;
    std::fs::write(path, svg)?;
    Ok(())
}

/// The outermost missing directory on the way to `path` (`out/plots` for `out/plots/a.svg`
/// when `out` is missing), if any.
fn missing_directory(path: &Path) -> Option<std::path::PathBuf> {
    let parent = path.parent().filter(|p| !p.as_os_str().is_empty())?;
    if parent.exists() {
        return None;
    }
    let missing = parent
        .ancestors()
        .take_while(|a| !a.as_os_str().is_empty() && !a.exists())
        .last()?;
    Some(missing.to_path_buf())
}

/// Renders the panels as an SVG document and returns it as a string (see [`write_svg`]).
pub fn render_svg(title: &str, x_label: &str, panels: &[Panel<'_>]) -> Result<String, PlotError> {
    let (w, h) = figure_size(panels.len());
    let mut svg = String::new();
    {
        let root = SVGBackend::with_string(&mut svg, (w * RES, h * RES)).into_drawing_area();
        draw_figure(&root, title, x_label, panels)?;
        root.present().map_err(draw_err)?;
    }
    // Declare the nominal size; the viewBox written by plotters maps the supersampled coordinates.
    let drawn = format!("<svg width=\"{}\" height=\"{}\"", w * RES, h * RES);
    let nominal = format!("<svg width=\"{w}\" height=\"{h}\"");
    if svg.starts_with(&drawn) {
        svg.replace_range(..drawn.len(), &nominal);
    }
    Ok(svg)
}

fn draw_figure<DB: DrawingBackend>(
    root: &DrawingArea<DB, Shift>,
    title: &str,
    x_label: &str,
    panels: &[Panel<'_>],
) -> Result<(), PlotError> {
    root.fill(&WHITE).map_err(draw_err)?;
    let m = px(MARGIN);
    let area = root.margin(m, m, m, m + px(8));
    let area = area
        .titled(
            title,
            ("sans-serif", px(24)).into_font().style(FontStyle::Bold),
        )
        .map_err(draw_err)?;
    if panels.is_empty() {
        return Ok(());
    }

    let x_range = padded_range(
        panels
            .iter()
            .flat_map(|p| p.series)
            .flat_map(|s| s.points)
            .map(|p| p.0),
        0.0,
    );
    // Panel bands: equal heights, the bottom one extended by the x axis area so all plot areas match.
    let breaks: Vec<i32> = (1..panels.len()).map(|i| i as i32 * px(PANEL_H)).collect();
    let bands = area.split_by_breakpoints::<i32, i32, _, _>([], breaks);

    let x_fmt = tick_formatter(&x_range);
    for (i, (panel, band)) in panels.iter().zip(&bands).enumerate() {
        let bottom = i + 1 == panels.len();
        let y_range = padded_range(
            panel.series.iter().flat_map(|s| s.points).map(|p| p.1),
            0.05,
        );
        let y_fmt = tick_formatter(&y_range);

        let mut chart = ChartBuilder::on(band)
            .margin_top(px(8))
            .margin_bottom(px(if bottom { 4 } else { 10 }))
            .margin_right(px(8))
            .x_label_area_size(if bottom { px(X_AXIS_H) } else { 0 })
            .y_label_area_size(px(Y_AXIS_W))
            .build_cartesian_2d(x_range.clone(), y_range.clone())
            .map_err(draw_err)?;

        let line = |c: RGBColor| c.stroke_width(RES);
        let text = ("sans-serif", px(14))
            .into_font()
            .color(&RGBColor(40, 40, 40));
        let desc = ("sans-serif", px(16)).into_font().color(&BLACK);
        let no_label = |_: &f64| String::new();
        let mut mesh = chart.configure_mesh();
        mesh.x_labels(10)
            .y_labels(6)
            .max_light_lines(4)
            .bold_line_style(line(RGBColor(205, 205, 205)))
            .light_line_style(line(RGBColor(238, 238, 238)))
            .axis_style(line(RGBColor(90, 90, 90)))
            .set_all_tick_mark_size(px(4))
            .x_label_offset(0)
            .label_style(text)
            .axis_desc_style(desc)
            .y_desc(panel.y_label)
            .y_label_formatter(&y_fmt);
        // Only the bottom panel carries the x tick labels and axis label; the others share its axis.
        if bottom {
            mesh.x_desc(x_label).x_label_formatter(&x_fmt);
        } else {
            mesh.x_label_formatter(&no_label);
        }
        mesh.draw().map_err(draw_err)?;

        let mut labelled = false;
        for (k, s) in panel.series.iter().enumerate() {
            let color = PALETTE[k % PALETTE.len()];
            let style = color.stroke_width(2 * RES);
            let drawn = chart
                .draw_series(
                    finite_runs(s.points)
                        .into_iter()
                        .map(|run| PathElement::new(run, style)),
                )
                .map_err(draw_err)?;
            if !s.name.is_empty() {
                labelled = true;
                drawn.label(s.name).legend(move |(x, y)| {
                    PathElement::new(vec![(x, y), (x + px(22), y)], color.stroke_width(2 * RES))
                });
            }
        }
        if labelled {
            chart
                .configure_series_labels()
                .position(SeriesLabelPosition::UpperRight)
                .background_style(WHITE.mix(0.9))
                .border_style(line(RGBColor(170, 170, 170)))
                .label_font(("sans-serif", px(14)))
                .margin(px(10))
                .legend_area_size(px(30))
                .draw()
                .map_err(draw_err)?;
        }
    }
    Ok(())
}

/// Splits a polyline into maximal runs of finite points, so gaps in the data show as gaps; values are
/// clipped to ±[`AXIS_LIMIT`].
fn finite_runs(points: &[(f64, f64)]) -> Vec<Vec<(f64, f64)>> {
    let mut runs = Vec::new();
    let mut run = Vec::new();
    for &(x, y) in points {
        if x.is_finite() && y.is_finite() {
            // Clip like the axis range does: plotters overflows i32 pixel arithmetic (a panic in debug
            // builds) on points far outside the chart.
            run.push((
                x.clamp(-AXIS_LIMIT, AXIS_LIMIT),
                y.clamp(-AXIS_LIMIT, AXIS_LIMIT),
            ));
        } else if !run.is_empty() {
            runs.push(core::mem::take(&mut run));
        }
    }
    if !run.is_empty() {
        runs.push(run);
    }
    runs
}

/// Largest magnitude an axis may reach. plotters' tick search misbehaves on infinite spans (it can
/// loop forever), so data beyond this are clipped to it: the figure stays valid, the curve is cut off.
const AXIS_LIMIT: f64 = 1e300;
/// Below this magnitude a constant value is treated as zero when choosing a band around it.
const TINY: f64 = 1e-200;

/// Range covering the finite values, widened by `pad` of its span on each side. Empty, constant or
/// nearly constant inputs (span below 1e-9 of the magnitude, where tick placement would be dominated by
/// round-off) get a band of ±half the magnitude (±1 around zero), so the mapping stays well defined.
fn padded_range(values: impl Iterator<Item = f64>, pad: f64) -> Range<f64> {
    let (lo, hi) = values
        .filter(|v| v.is_finite())
        .map(|v| v.clamp(-AXIS_LIMIT, AXIS_LIMIT))
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), v| {
            (lo.min(v), hi.max(v))
        });
    if lo > hi {
        return 0.0..1.0;
    }
    let span = hi - lo; // at most 2e300: finite
    let mag = lo.abs().max(hi.abs());
    if span < (1e-9 * mag).max(TINY) {
        let c = 0.5 * (lo + hi);
        let half = if c.abs() < TINY { 1.0 } else { 0.5 * c.abs() };
        return (c - half)..(c + half);
    }
    (lo - pad * span)..(hi + pad * span)
}

/// Tick label formatter for an axis over `range`: plain decimals with just enough digits for the tick
/// spacing, or compact scientific notation for very large or very small magnitudes.
fn tick_formatter(range: &Range<f64>) -> impl Fn(&f64) -> String + use<> {
    let span = (range.end - range.start).abs();
    let mag = range.start.abs().max(range.end.abs());
    // plotters chooses ticks at 1, 2 or 5 × 10^k with roughly ten per axis.
    let step_exp = if span > 0.0 && span.is_finite() {
        (span / 10.0).log10().floor() as i32
    } else {
        0
    };
    let scientific = mag.is_finite() && (mag >= 1e5 || (mag > 0.0 && mag < 1e-3));
    let mag_exp = if mag > 0.0 && mag.is_finite() {
        mag.log10().floor() as i32
    } else {
        0
    };
    move |v: &f64| {
        let v = *v;
        if v == 0.0 || (span > 0.0 && v.abs() < span * 1e-9) {
            // Avoid labels like "-1.2e-14" at a tick that is zero up to round-off.
            "0".to_string()
        } else if scientific {
            let prec = (mag_exp - step_exp).clamp(0, 6) as usize;
            format!("{v:.prec$e}")
        } else {
            let prec = (-step_exp).clamp(0, 8) as usize;
            format!("{v:.prec$}")
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn temp_path(tag: &str) -> std::path::PathBuf {
        let nanos = std::time::SystemTime::now()
            .duration_since(std::time::UNIX_EPOCH)
            .map(|d| d.as_nanos())
            .unwrap_or(0);
        std::env::temp_dir().join(format!(
            "mechgen-plot-{tag}-{}-{nanos}.svg",
            std::process::id()
        ))
    }

    fn looks_like_svg(svg: &str) {
        assert!(
            svg.trim_start().starts_with("<svg"),
            "{}",
            &svg[..svg.len().min(200)]
        );
        assert!(svg.trim_end().ends_with("</svg>"));
    }

    #[test]
    fn writes_piston_like_figure_with_labels() {
        let pc = crate::closed_form::PistonCrank::default();
        let n = 361;
        let mut pos = Vec::new();
        let mut vel = Vec::new();
        let mut acc = Vec::new();
        for i in 0..n {
            let t = pc.period() * i as f64 / (n - 1) as f64;
            let k = pc.kinematics(t);
            let deg = k.q[11].to_degrees();
            pos.push((deg, k.q[3]));
            vel.push((deg, k.qd[3] / 1000.0));
            acc.push((deg, k.qdd[3]));
        }
        let path = temp_path("piston");
        write_svg(
            &path,
            "Seed piston-crank: piston kinematics",
            "crank angle (deg)",
            &[
                Panel {
                    y_label: "position (mm)",
                    series: &[Series {
                        name: "piston.x",
                        points: &pos,
                    }],
                },
                Panel {
                    y_label: "velocity (m/s)",
                    series: &[Series {
                        name: "piston.ẋ",
                        points: &vel,
                    }],
                },
                Panel {
                    y_label: "acceleration (mm/s²)",
                    series: &[Series {
                        name: "piston.ẍ",
                        points: &acc,
                    }],
                },
            ],
        )
        .expect("plot written");
        let svg = std::fs::read_to_string(&path).expect("read back");
        looks_like_svg(&svg);
        for needle in [
            "Seed piston-crank: piston kinematics",
            "crank angle (deg)",
            "position (mm)",
            "velocity (m/s)",
            "acceleration (mm/s²)",
            "piston.x",
            "<polyline",
        ] {
            assert!(svg.contains(needle), "missing {needle:?}");
        }
        assert_eq!(figure_size(3), (900, 900));
        if std::env::var_os("MECHGEN_KEEP_PLOT").is_none() {
            let _ = std::fs::remove_file(&path);
        } else {
            eprintln!("plot kept at {}", path.display());
        }
    }

    #[test]
    fn degenerate_inputs_still_give_valid_svg() {
        let nan = f64::NAN;
        let inf = f64::INFINITY;
        let weird = [(0.0, 1.0), (nan, 2.0), (1.0, inf), (2.0, 3.0), (3.0, 3.0)];
        let constant = [(5.0, 7.0), (6.0, 7.0)];
        let all_bad = [(nan, nan), (inf, -inf)];
        let huge = [(0.0, f64::MAX), (1.0, -f64::MAX)];
        let nearly_constant = [(0.0, 1.0), (1.0, 1.0 + 1e-13), (1e-300, 1.0)];
        let tiny = [(1e-250, 1e-250), (2e-250, 3e-250)];
        let gaps = [
            Series {
                name: "a",
                points: &weird,
            },
            Series {
                name: "",
                points: &constant,
            },
        ];
        let bad = [Series {
            name: "bad",
            points: &all_bad,
        }];
        let big = [Series {
            name: "huge",
            points: &huge,
        }];
        let small = [
            Series {
                name: "nearly constant",
                points: &nearly_constant,
            },
            Series {
                name: "tiny",
                points: &tiny,
            },
        ];
        let cases: Vec<Vec<Panel<'_>>> = vec![
            vec![],
            vec![Panel {
                y_label: "empty",
                series: &[],
            }],
            vec![Panel {
                y_label: "empty series",
                series: &[Series {
                    name: "none",
                    points: &[],
                }],
            }],
            vec![
                Panel {
                    y_label: "gaps",
                    series: &gaps,
                },
                Panel {
                    y_label: "all non-finite",
                    series: &bad,
                },
                Panel {
                    y_label: "huge",
                    series: &big,
                },
                Panel {
                    y_label: "small",
                    series: &small,
                },
            ],
        ];
        for panels in &cases {
            let svg = render_svg("Degenerate", "x (1)", panels).expect("rendered");
            looks_like_svg(&svg);
            assert!(svg.contains("Degenerate"));
            for p in panels {
                assert!(svg.contains(p.y_label));
            }
        }
        let path = temp_path("empty");
        write_svg(&path, "Empty", "x", &[]).expect("written");
        looks_like_svg(&std::fs::read_to_string(&path).expect("read back"));
        let _ = std::fs::remove_file(&path);
    }

    #[test]
    fn missing_directories_are_named_not_created() {
        let top = temp_path("missing").with_extension("");
        let path = top.join("plots").join("a.svg");
        let error = write_svg(&path, "T", "x", &[]).expect_err("no directory");
        let message = error.to_string();
        assert!(
            message.contains(&format!("`{}` does not exist", top.display())),
            "{message}"
        );
        assert!(!top.exists(), "nothing created");
    }

    #[test]
    fn finite_runs_break_at_gaps() {
        let runs = finite_runs(&[
            (0.0, 0.0),
            (1.0, f64::NAN),
            (2.0, 2.0),
            (3.0, 3.0),
            (f64::INFINITY, 0.0),
        ]);
        assert_eq!(runs, vec![vec![(0.0, 0.0)], vec![(2.0, 2.0), (3.0, 3.0)]]);
    }

    #[test]
    fn ranges_and_ticks() {
        assert_eq!(padded_range([].into_iter(), 0.1), 0.0..1.0);
        assert_eq!(padded_range([2.0, 2.0].into_iter(), 0.1), 1.0..3.0);
        assert_eq!(padded_range([0.0].into_iter(), 0.1), -1.0..1.0);
        assert_eq!(padded_range([f64::MAX, 0.0].into_iter(), 0.0), 0.0..1e300);
        let f = tick_formatter(&(0.0..360.0));
        assert_eq!(f(&90.0), "90");
        let f = tick_formatter(&(-2.0e6..2.0e6));
        assert_eq!(f(&1.5e6), "1.5e6");
        let f = tick_formatter(&(-0.5..0.5));
        assert_eq!(f(&0.2), "0.2");
        assert_eq!(f(&1e-17), "0");
    }
}
