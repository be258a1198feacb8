//! The work-precision diagram: error against run time per step, both on log scales, one curve
//! per method, with markers telling the swept settings apart and the legend beside the plot.
//!
//! Axes are drawn in decades: the data are mapped to log10 and the ticks at whole powers of ten
//! are labelled (`1e-12`; `0.1`, `1`, `10` µs). Like [`crate::plot`], nothing is trusted: points
//! that are not finite and positive are skipped (the line breaks there), errors below
//! [`ERROR_FLOOR`] (an exact result) are drawn at the floor, and empty inputs still give a valid
//! SVG.

use crate::plot::{PALETTE, RES, px};
use std::ops::Range;

use plotters::coord::Shift;
use plotters::element::DashedPathElement;
use plotters::prelude::*;
use plotters::style::text_anchor::{HPos, Pos, VPos};

use crate::plot::PlotError;

/// Errors below this are drawn at it (log scales cannot show zero).
pub const ERROR_FLOOR: f64 = 1e-17;

/// Figure size, px.
const WIDTH: u32 = 980;
const HEIGHT: u32 = 620;
/// Width of the legend column right of the plot, px.
const LEGEND_W: u32 = 290;
/// Marker shape of a curve's points.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Marker {
    /// Filled circle.
    Circle,
    /// Filled triangle.
    Triangle,
    /// Diagonal cross.
    Cross,
}

/// One curve: points (seconds per step, relative error) joined in order.
#[derive(Debug, Clone, Copy)]
pub struct Curve<'a> {
    /// Legend entry (empty: none).
    pub name: &'a str,
    /// Palette index (the method).
    pub colour: usize,
    /// Marker of every point.
    pub marker: Marker,
    /// Thin dashed line instead of a solid one.
    pub dashed: bool,
    /// `(seconds per step, relative error)`, in drawing order.
    pub points: &'a [(f64, f64)],
    /// Text beside each point (same order; missing or empty entries draw nothing). A label
    /// that would overprint an earlier one is left out.
    pub annotations: &'a [String],
    /// Put the labels left of the points (else right).
    pub annotate_left: bool,
}

/// A legend entry explaining a marker (drawn in grey, independent of colour).
#[derive(Debug, Clone, Copy)]
pub struct Key<'a> {
    /// The marker.
    pub marker: Marker,
    /// Dashed line beside it.
    pub dashed: bool,
    /// What it stands for.
    pub text: &'a str,
}

/// Renders the diagram as an SVG document.
///
/// # Errors
/// [`PlotError::Draw`] if plotters fails.
pub fn render(title: &str, curves: &[Curve<'_>], keys: &[Key<'_>]) -> Result<String, PlotError> {
    let mut svg = String::new();
    {
        let root =
            SVGBackend::with_string(&mut svg, (WIDTH * RES, HEIGHT * RES)).into_drawing_area();
        draw(&root, title, curves, keys)?;
        root.present().map_err(draw_err)?;
    }
    let drawn = format!("<svg width=\"{}\" height=\"{}\"", WIDTH * RES, HEIGHT * RES);
    let nominal = format!("<svg width=\"{WIDTH}\" height=\"{HEIGHT}\"");
    if svg.starts_with(&drawn) {
        svg.replace_range(..drawn.len(), &nominal);
    }
    Ok(svg)
}

fn draw_err<E: core::fmt::Debug>(e: E) -> PlotError {
    PlotError::Draw(format!("{e:?}"))
}

/// A point in log10 coordinates (µs, error), or `None` if it cannot be drawn.
fn to_log((seconds, error): (f64, f64)) -> Option<(f64, f64)> {
    let micros = seconds * 1e6;
    if !(micros.is_finite() && micros > 0.0) || error.is_nan() || error.is_infinite() {
        return None;
    }
    Some((micros.log10(), error.max(ERROR_FLOOR).log10()))
}

/// Whole decades covering the values (at least one decade; `fallback` when there are none).
fn decades(values: impl Iterator<Item = f64>, fallback: Range<f64>) -> Range<f64> {
    let (lo, hi) = values
        .filter(|v| v.is_finite())
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), v| {
            (lo.min(v), hi.max(v))
        });
    if lo > hi {
        return fallback;
    }
    // A little air so that points on a decade line do not sit on the frame.
    let (lo, hi) = ((lo - 0.05).floor(), (hi + 0.05).ceil());
    if hi - lo < 1.0 { lo..lo + 1.0 } else { lo..hi }
}

/// Tick label for a log10 position: only whole decades are labelled.
fn decade_label(v: f64, decimal: bool) -> String {
    let rounded = v.round();
    if (v - rounded).abs() > 1e-6 {
        return String::new();
    }
    let exponent = rounded as i32;
    if decimal && (-3..=4).contains(&exponent) {
        let value = 10f64.powi(exponent);
        let digits = (-exponent).max(0) as usize;
        format!("{value:.digits$}")
    } else {
        format!("1e{exponent}")
    }
}

fn draw<DB: DrawingBackend>(
    root: &DrawingArea<DB, Shift>,
    title: &str,
    curves: &[Curve<'_>],
    keys: &[Key<'_>],
) -> Result<(), PlotError> {
    root.fill(&WHITE).map_err(draw_err)?;
    let area = root.margin(px(12), px(12), px(12), px(12));
    let area = area
        .titled(
            title,
            ("sans-serif", px(20)).into_font().style(FontStyle::Bold),
        )
        .map_err(draw_err)?;
    let (plot_area, legend_area) = area.split_horizontally(px(WIDTH - LEGEND_W - 24));

    let logged: Vec<Vec<Option<(f64, f64)>>> = curves
        .iter()
        .map(|c| c.points.iter().map(|&p| to_log(p)).collect())
        .collect();
    let all = || logged.iter().flatten().flatten();
    let x_range = decades(all().map(|p| p.0), 0.0..2.0);
    let y_range = decades(all().map(|p| p.1), -16.0..0.0);

    let mut chart = ChartBuilder::on(&plot_area)
        .margin_top(px(8))
        .margin_right(px(12))
        .x_label_area_size(px(56))
        .y_label_area_size(px(78))
        .build_cartesian_2d(x_range.clone(), y_range.clone())
        .map_err(draw_err)?;
    let grey = |v: u8| RGBColor(v, v, v);
    let x_decades = (x_range.end - x_range.start).round() as usize;
    let y_decades = (y_range.end - y_range.start).round() as usize;
    let x_format = |v: &f64| decade_label(*v, true);
    let y_format = |v: &f64| decade_label(*v, false);
    chart
        .configure_mesh()
        .x_labels(x_decades + 1)
        .y_labels(y_decades + 1)
        .max_light_lines(0)
        .bold_line_style(grey(220).stroke_width(RES))
        .axis_style(grey(90).stroke_width(RES))
        .set_all_tick_mark_size(px(4))
        .label_style(("sans-serif", px(14)).into_font().color(&grey(40)))
        .axis_desc_style(("sans-serif", px(15)).into_font().color(&BLACK))
        .x_desc("time per step (µs, log scale)")
        .y_desc("max relative error of q, q̇, q̈ (log scale)")
        .x_label_formatter(&x_format)
        .y_label_formatter(&y_format)
        .draw()
        .map_err(draw_err)?;

    // Annotations that would overprint an earlier one are left out (coinciding points).
    let (width, height) = chart.plotting_area().dim_in_pixel();
    let pixels = |(x, y): (f64, f64)| {
        (
            (x - x_range.start) / (x_range.end - x_range.start) * f64::from(width),
            (y - y_range.start) / (y_range.end - y_range.start) * f64::from(height),
        )
    };
    let mut labelled: Vec<[f64; 4]> = Vec::new();
    for (curve, points) in curves.iter().zip(&logged) {
        let colour = PALETTE[curve.colour % PALETTE.len()];
        for run in runs(points) {
            if curve.dashed {
                chart
                    .draw_series(std::iter::once(DashedPathElement::new(
                        run,
                        px(5),
                        px(4),
                        colour.stroke_width(RES),
                    )))
                    .map_err(draw_err)?;
            } else {
                chart
                    .draw_series(std::iter::once(PathElement::new(
                        run,
                        colour.stroke_width(2 * RES),
                    )))
                    .map_err(draw_err)?;
            }
        }
        let plotting = chart.plotting_area();
        for (k, point) in points.iter().enumerate() {
            let Some(at) = *point else { continue };
            draw_marker(plotting, at, curve.marker, colour)?;
            let Some(text) = curve.annotations.get(k).filter(|t| !t.is_empty()) else {
                continue;
            };
            // The label's box in pixels (y up), beside the point on the chosen side.
            let (x, y) = pixels(at);
            let (gap, width) = (
                f64::from(px(6)),
                text.chars().count() as f64 * f64::from(px(7)),
            );
            let left = if curve.annotate_left {
                x - gap - width
            } else {
                x + gap
            };
            let label_box = [
                left,
                y - f64::from(px(16)),
                left + width,
                y - f64::from(px(4)),
            ];
            let overlaps = |b: &[f64; 4]| {
                label_box[0] < b[2]
                    && b[0] < label_box[2]
                    && label_box[1] < b[3]
                    && b[1] < label_box[3]
            };
            if !labelled.iter().any(overlaps) {
                labelled.push(label_box);
                let (offset, anchor) = if curve.annotate_left {
                    ((-px(6), px(4)), HPos::Right)
                } else {
                    ((px(6), px(4)), HPos::Left)
                };
                let style = ("sans-serif", px(11))
                    .into_font()
                    .color(&grey(70))
                    .pos(Pos::new(anchor, VPos::Top));
                let label = EmptyElement::at(at) + Text::new(text.clone(), offset, style);
                plotting.draw(&label).map_err(draw_err)?;
            }
        }
    }

    draw_legend(&legend_area, curves, keys)
}

/// Maximal runs of drawable points (lines break at the others).
fn runs(points: &[Option<(f64, f64)>]) -> Vec<Vec<(f64, f64)>> {
    let mut runs = Vec::new();
    let mut run = Vec::new();
    for point in points {
        match point {
            Some(p) => run.push(*p),
            None if !run.is_empty() => runs.push(std::mem::take(&mut run)),
            None => {}
        }
    }
    if !run.is_empty() {
        runs.push(run);
    }
    runs
}

fn draw_marker<DB: DrawingBackend, CT: CoordTranslate>(
    area: &DrawingArea<DB, CT>,
    at: CT::From,
    marker: Marker,
    colour: RGBColor,
) -> Result<(), PlotError> {
    let base = EmptyElement::at(at);
    let drawn = match marker {
        Marker::Circle => area.draw(&(base + Circle::new((0, 0), px(4), colour.filled()))),
        Marker::Triangle => {
            area.draw(&(base + TriangleMarker::new((0, 0), px(5), colour.filled())))
        }
        Marker::Cross => area.draw(&(base + Cross::new((0, 0), px(4), colour.stroke_width(RES)))),
    };
    drawn.map_err(draw_err)
}

/// The legend column: one colour per named curve, then the marker keys.
fn draw_legend<DB: DrawingBackend>(
    area: &DrawingArea<DB, Shift>,
    curves: &[Curve<'_>],
    keys: &[Key<'_>],
) -> Result<(), PlotError> {
    let font = ("sans-serif", px(14)).into_font().color(&BLACK);
    let line_height = px(24);
    let (x0, mut y) = (px(8), px(24));
    for curve in curves.iter().filter(|c| !c.name.is_empty()) {
        let colour = PALETTE[curve.colour % PALETTE.len()];
        area.draw(&PathElement::new(
            vec![(x0, y), (x0 + px(28), y)],
            colour.stroke_width(2 * RES),
        ))
        .map_err(draw_err)?;
        draw_marker(area, (x0 + px(14), y), curve.marker, colour)?;
        area.draw(&Text::new(
            curve.name.to_string(),
            (x0 + px(38), y - px(8)),
            font.clone(),
        ))
        .map_err(draw_err)?;
        y += line_height;
    }
    y += line_height / 2;
    let grey = RGBColor(90, 90, 90);
    for key in keys {
        if key.dashed {
            area.draw(&DashedPathElement::new(
                vec![(x0, y), (x0 + px(28), y)],
                px(5),
                px(4),
                grey.stroke_width(RES),
            ))
            .map_err(draw_err)?;
        } else {
            area.draw(&PathElement::new(
                vec![(x0, y), (x0 + px(28), y)],
                grey.stroke_width(2 * RES),
            ))
            .map_err(draw_err)?;
        }
        draw_marker(area, (x0 + px(14), y), key.marker, grey)?;
        // Keys may be long: wrap at the legend's width on spaces.
        for line in wrap(key.text, 30) {
            area.draw(&Text::new(line, (x0 + px(38), y - px(8)), font.clone()))
                .map_err(draw_err)?;
            y += px(18);
        }
        y += px(10);
    }
    Ok(())
}

/// Splits `text` into lines of at most about `width` characters at spaces.
fn wrap(text: &str, width: usize) -> Vec<String> {
    let mut lines = Vec::new();
    let mut line = String::new();
    for word in text.split_whitespace() {
        if !line.is_empty() && line.chars().count() + 1 + word.chars().count() > width {
            lines.push(std::mem::take(&mut line));
        }
        if !line.is_empty() {
            line.push(' ');
        }
        line.push_str(word);
    }
    if !line.is_empty() {
        lines.push(line);
    }
    lines
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn labels_decades_only() {
        assert_eq!(decade_label(-12.0, false), "1e-12");
        assert_eq!(decade_label(-11.5, false), "");
        assert_eq!(decade_label(0.0, true), "1");
        assert_eq!(decade_label(-1.0, true), "0.1");
        assert_eq!(decade_label(2.0, true), "100");
        assert_eq!(decade_label(5.0, true), "1e5");
    }

    #[test]
    fn ranges_are_whole_decades() {
        assert_eq!(decades([0.3, 1.2].into_iter(), 0.0..1.0), 0.0..2.0);
        assert_eq!(decades([-12.5].into_iter(), 0.0..1.0), -13.0..-12.0);
        assert_eq!(decades([f64::NAN].into_iter(), 0.0..1.0), 0.0..1.0);
        assert_eq!(to_log((1e-6, 0.0)), Some((0.0, -17.0)));
        assert_eq!(to_log((0.0, 1.0)), None);
        assert_eq!(to_log((1e-6, f64::INFINITY)), None);
    }

    #[test]
    fn degenerate_data_still_render() {
        let bad = [(f64::NAN, 1.0), (-1.0, 1e-3), (1e-6, f64::INFINITY)];
        let good = [(2e-6, 1e-15), (3e-6, 1e-9), (1e-5, 0.0)];
        let notes = vec!["a".to_string()];
        let curves = [
            Curve {
                name: "bad",
                colour: 0,
                marker: Marker::Circle,
                dashed: false,
                points: &bad,
                annotations: &[],
                annotate_left: false,
            },
            Curve {
                name: "good",
                colour: 7,
                marker: Marker::Cross,
                dashed: true,
                points: &good,
                annotations: &notes,
                annotate_left: true,
            },
        ];
        let keys = [Key {
            marker: Marker::Triangle,
            dashed: false,
            text: "a long explanation that wraps over several lines of the legend",
        }];
        for (c, k) in [(&curves[..], &keys[..]), (&[][..], &[][..])] {
            let svg = render("Title", c, k).expect("renders");
            assert!(svg.starts_with("<svg width=\"980\""));
            assert!(svg.trim_end().ends_with("</svg>"));
        }
    }
}
