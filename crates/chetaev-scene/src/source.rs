//! From byte offsets in a scene file to lines, columns and a quoted line with a caret.

use std::ops::Range;

/// A position in a scene file: 1-based line and column (the column counts characters).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Position {
    /// Line, from 1.
    pub line: usize,
    /// Column, from 1, in characters.
    pub column: usize,
}

/// The line and column of byte `offset` in `text`.
pub fn position(text: &str, offset: usize) -> Position {
    let offset = floor_char_boundary(text, offset.min(text.len()));
    let before = &text[..offset];
    let line = before.matches('\n').count() + 1;
    let line_start = before.rfind('\n').map_or(0, |i| i + 1);
    let column = text[line_start..offset].chars().count() + 1;
    Position { line, column }
}

fn floor_char_boundary(text: &str, mut i: usize) -> usize {
    while i > 0 && !text.is_char_boundary(i) {
        i -= 1;
    }
    i
}

/// The line holding `range.start`, and a marker line under the range (at least one caret),
/// prefixed with the line number as compilers do:
///
/// ```text
///    |
/// 14 | constraints = ["x_dot^^2 + y_dot^2 - v0^2"]
///    |                       ^
/// ```
pub fn snippet(text: &str, range: Range<usize>) -> String {
    let start = floor_char_boundary(text, range.start.min(text.len()));
    let pos = position(text, start);
    let line_start = text[..start].rfind('\n').map_or(0, |i| i + 1);
    let line_end = text[start..].find('\n').map_or(text.len(), |i| start + i);
    let line = text[line_start..line_end].trim_end_matches('\r');
    let end = floor_char_boundary(text, range.end.clamp(start, line_end));
    let width = text[start..end].chars().count().max(1);
    let number = pos.line.to_string();
    let pad = " ".repeat(number.len());
    // Tabs keep their width in the marker line so the caret stays under the text.
    let lead: String = text[line_start..start]
        .chars()
        .map(|c| if c == '\t' { '\t' } else { ' ' })
        .collect();
    format!(
        "{pad} |\n{number} | {line}\n{pad} | {lead}{}",
        "^".repeat(width)
    )
}

/// Maps a byte offset inside the decoded value of a TOML string to the byte offset in the file,
/// given the span `span` of the string literal (quotes included) in `text`.
///
/// Literal strings (`'...'`, `'''...'''`) map one to one; basic strings (`"..."`, `"""..."""`) are
/// walked escape by escape. Where the literal cannot be matched to `decoded` the start of the
/// string is returned.
pub fn string_offset(text: &str, span: &Range<usize>, decoded: &str, index: usize) -> usize {
    let Some(raw) = text.get(span.clone()) else {
        return span.start.min(text.len());
    };
    let (open, basic) = if raw.starts_with("\"\"\"") {
        (3, true)
    } else if raw.starts_with("'''") {
        (3, false)
    } else if raw.starts_with('"') {
        (1, true)
    } else if raw.starts_with('\'') {
        (1, false)
    } else {
        return span.start;
    };
    let mut r = open;
    // A newline right after the opening delimiter of a multi-line string is not part of the value.
    if open == 3 {
        if raw[r..].starts_with("\r\n") {
            r += 2;
        } else if raw[r..].starts_with('\n') {
            r += 1;
        }
    }
    let raw_b = raw.as_bytes();
    let mut d = 0;
    while d < index.min(decoded.len()) {
        if r >= raw.len() {
            return span.start;
        }
        if basic && raw_b[r] == b'\\' {
            let next = raw_b.get(r + 1).copied().unwrap_or(b' ');
            match next {
                b'u' => r += 6,
                b'U' => r += 10,
                b' ' | b'\t' | b'\r' | b'\n' => {
                    // Line-ending backslash: the backslash and all following whitespace vanish.
                    r += 1;
                    while r < raw.len() && matches!(raw_b[r], b' ' | b'\t' | b'\r' | b'\n') {
                        r += 1;
                    }
                    continue;
                }
                _ => r += 2,
            }
            d += decoded[d..].chars().next().map_or(1, char::len_utf8);
            continue;
        }
        let Some(c) = raw.get(r..).and_then(|rest| rest.chars().next()) else {
            return span.start;
        };
        r += c.len_utf8();
        d += c.len_utf8();
    }
    span.start + r
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn lines_and_columns() {
        let t = "a = 1\nb = \"x^^2\"\n";
        assert_eq!(position(t, 0), Position { line: 1, column: 1 });
        assert_eq!(position(t, 12), Position { line: 2, column: 7 });
    }

    #[test]
    fn maps_offsets_through_escapes_and_quotes() {
        let t = r#"k = "a\tb^^" "#;
        let span = 4..12;
        // decoded: a, TAB, b, ^, ^ ; the second ^ is at decoded byte 4, file byte 10.
        assert_eq!(string_offset(t, &span, "a\tb^^", 4), 10);
        let t = "k = 'x ^^'";
        assert_eq!(string_offset(t, &(4..10), "x ^^", 3), 8);
        let t = "k = \"\"\"\nx^^2\"\"\"";
        assert_eq!(string_offset(t, &(4..15), "x^^2", 2), 10);
    }

    #[test]
    fn snippet_marks_the_range() {
        let s = snippet("first\nk = \"x^^2\"\n", 13..14);
        assert_eq!(s, format!("  |\n2 | k = \"x^^2\"\n  | {}^", " ".repeat(7)));
    }
}
