//! Mitsuba's curve files, read by its `linearcurve` and `bsplinecurve` shapes
//! (`src/shapes/linearcurve.cpp`, `src/shapes/bsplinecurve.cpp`): text, one control point
//! `x y z radius` per line, blank lines (spaces, tabs and carriage returns only) between
//! curves, each curve of at least two points (linear) or four (B-spline).
//!
//! As Mitsuba, lines of 1024 characters or more are refused, and there are no comments. Prism is
//! stricter where Mitsuba would read nonsense: a line must hold exactly four numbers (Mitsuba
//! ignores what follows the fourth) and a radius may not be negative.

use std::path::Path;

use glam::Vec4;

use crate::file_cache;
use prism_core::error::{Error, Result, SourceLocation};

/// The longest line Mitsuba's reader takes, in bytes (its buffer of 1025 less the terminator).
const MAX_LINE: usize = 1023;

/// Control points of a curve file, in the file's coordinates.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct CurveData {
    /// Position in xyz, radius in w.
    pub points: Vec<Vec4>,
    /// The index of each curve's first point; a curve runs to the next one's first point.
    pub curves: Vec<u32>,
}

/// Reads a curve file (see the module documentation) whose curves have at least `min_points`
/// control points each.
pub fn load_curves(path: &Path, min_points: usize) -> Result<CurveData> {
    let bytes = file_cache::read(path).map_err(|e| Error::io(path, &e, "read the curves"))?;
    parse_curves(&bytes, path, min_points)
}

/// Parses the bytes of a curve file whose curves have at least `min_points` control points
/// each; `path` names it in errors, which give the line and column.
pub fn parse_curves(bytes: &[u8], path: &Path, min_points: usize) -> Result<CurveData> {
    let mut data = CurveData::default();
    // The line where the curve being read began, to name it if it ends too short.
    let mut open: Option<usize> = None;
    let close = |data: &CurveData, open: Option<usize>| -> Result<()> {
        match (open, data.curves.last()) {
            (Some(line), Some(&first)) if data.points.len() - (first as usize) < min_points => {
                let count = data.points.len() - first as usize;
                let has = if count == 1 {
                    "a single control point".to_string()
                } else {
                    format!("{count} control points")
                };
                Err(Error::input(
                    &location(path, line, 1),
                    format!("this curve has {has}; a curve here needs at least {min_points}"),
                )
                .with_help("add points, or remove the blank line that splits the curve"))
            }
            _ => Ok(()),
        }
    };
    for (number, raw) in bytes.split(|&b| b == b'\n').enumerate() {
        if raw.len() > MAX_LINE {
            return Err(Error::input(
                &location(path, number, 1),
                format!(
                    "line of {} characters: curve files (as Mitsuba's) allow at most {MAX_LINE}",
                    raw.len()
                ),
            ));
        }
        let line = std::str::from_utf8(raw).map_err(|e| {
            Error::input(
                &location(path, number, e.valid_up_to() as u32 + 1),
                "not UTF-8 text: a curve file holds numbers `x y z radius`, one point per line",
            )
        })?;
        if line.trim_matches([' ', '\t', '\r']).is_empty() {
            close(&data, open)?;
            open = None;
            continue;
        }
        let words: Vec<&str> = line
            .split([' ', '\t', '\r'])
            .filter(|w| !w.is_empty())
            .collect();
        let column = |word: &str| (word.as_ptr() as usize - line.as_ptr() as usize) as u32 + 1;
        if words.len() != 4 {
            let at = words.get(4).map_or(1, |w| column(w));
            return Err(Error::input(
                &location(path, number, at),
                format!(
                    "{} numbers on a line; a control point is `x y z radius`",
                    words.len()
                ),
            )
            .with_help("one point per line, a blank line between curves (no comments)"));
        }
        let mut values = [0.0f32; 4];
        for (value, word) in values.iter_mut().zip(&words) {
            *value = word
                .parse::<f32>()
                .ok()
                .filter(|v| v.is_finite())
                .ok_or_else(|| {
                    Error::input(
                        &location(path, number, column(word)),
                        format!("\"{word}\" is not a finite number"),
                    )
                })?;
        }
        if values[3] < 0.0 {
            return Err(Error::input(
                &location(path, number, column(words[3])),
                format!("the radius {} is negative", values[3]),
            ));
        }
        if open.is_none() {
            let first = u32::try_from(data.points.len())
                .ok()
                .filter(|&n| n < u32::MAX)
                .ok_or_else(|| {
                    Error::input(
                        &location(path, number, 1),
                        "more than 2³² − 1 control points",
                    )
                })?;
            data.curves.push(first);
            open = Some(number);
        }
        data.points.push(Vec4::from_array(values));
    }
    close(&data, open)?;
    if data.points.is_empty() {
        return Err(Error::usage(format!(
            "{}: the curve file holds no control points",
            path.display()
        )));
    }
    Ok(data)
}

/// The location of a 0-based line `number`.
fn location(path: &Path, number: usize, column: u32) -> SourceLocation {
    let line = u32::try_from(number + 1).unwrap_or(u32::MAX);
    SourceLocation::new(path, line, column)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn parse(text: &str) -> Result<CurveData> {
        parse_curves(text.as_bytes(), Path::new("c.txt"), 2)
    }

    #[test]
    fn blank_lines_separate_curves() {
        let data = parse(
            "-1 0.1 0.1 0.5\n1 1.4 1.2 0.5\n \t\r\n\n-1 5 2.2 1\r\n-2.3 4 2.3 2\n4 1 2.2 5\n",
        )
        .unwrap();
        assert_eq!(data.points.len(), 5);
        assert_eq!(data.curves, vec![0, 2]);
        assert_eq!(data.points[2], Vec4::new(-1.0, 5.0, 2.2, 1.0));
    }

    #[test]
    fn bad_lines_are_named_by_line_and_column() {
        let message = |text: &str| parse(text).unwrap_err().to_string();
        let m = message("0 0 0 1\n1 1 x 1\n");
        assert!(m.contains("c.txt:2:5") && m.contains("\"x\""), "{m}");
        let m = message("0 0 0 1\n1 1 1 1 9\n");
        assert!(m.contains("c.txt:2:9") && m.contains("5 numbers"), "{m}");
        let m = message("0 0 0 1\n1 1 1 -2\n");
        assert!(m.contains("c.txt:2:7") && m.contains("negative"), "{m}");
        let m = message("0 0 0 1\n1 1 1 1\n\n2 2 2 1\n");
        assert!(
            m.contains("c.txt:4:1") && m.contains("single control point"),
            "{m}"
        );
        let m = message("# comment\n");
        assert!(m.contains("c.txt:1:1"), "{m}");
        let m = message("0 0 0 inf\n1 1 1 1\n");
        assert!(m.contains("not a finite number"), "{m}");
        let m = message(&format!("0 0 0 1{}\n", " ".repeat(1100)));
        assert!(m.contains("c.txt:1:1") && m.contains("1023"), "{m}");
        let m = message("\n\n");
        assert!(m.contains("no control points"), "{m}");
    }

    #[test]
    fn b_spline_curves_need_four_points() {
        let four = "0 0 0 1\n1 0 0 1\n2 0 0 1\n3 0 0 1\n";
        let path = Path::new("b.txt");
        let data = parse_curves(four.as_bytes(), path, 4).unwrap();
        assert_eq!((data.points.len(), data.curves.clone()), (4, vec![0]));
        let text = format!("{four}\n4 0 0 1\n5 0 0 1\n6 0 0 1\n");
        let m = parse_curves(text.as_bytes(), path, 4)
            .unwrap_err()
            .to_string();
        assert!(
            m.contains("b.txt:6:1") && m.contains("3 control points") && m.contains("at least 4"),
            "{m}"
        );
    }
}
