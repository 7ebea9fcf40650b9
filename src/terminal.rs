//! Text bound for a terminal or a log. Names, paths and URIs come from files, and a file
//! may hold control characters: an escape sequence that clears the screen or sets the
//! window title, or a newline that forges a second `error:` line. Every line gridtrace
//! prints passes through [`escaped`], which writes such characters as Rust-style escapes
//! (`\x1b`, `\n`, `\u{202e}`), so what reaches the terminal is exactly one visible line.

use std::borrow::Cow;
use std::fmt::Display;

/// True for a character that must not reach a terminal as it is: the C0 and C1 controls,
/// DEL, and the Unicode bidirectional overrides and isolates (which reorder what follows
/// them on screen; "Trojan Source", Boucher & Anderson 2021).
fn is_unsafe(c: char) -> bool {
    c.is_control() || matches!(c, '\u{202a}'..='\u{202e}' | '\u{2066}'..='\u{2069}')
}

/// `text` with every unsafe character escaped; borrowed when there is none.
pub fn escaped(text: &str) -> Cow<'_, str> {
    if !text.contains(is_unsafe) {
        return Cow::Borrowed(text);
    }
    let mut out = String::with_capacity(text.len() + 8);
    for c in text.chars() {
        match c {
            '\n' => out.push_str("\\n"),
            '\r' => out.push_str("\\r"),
            '\t' => out.push_str("\\t"),
            c if is_unsafe(c) && (c as u32) < 0x100 => {
                out.push_str(&format!("\\x{:02x}", c as u32));
            }
            c if is_unsafe(c) => out.push_str(&format!("\\u{{{:x}}}", c as u32)),
            c => out.push(c),
        }
    }
    Cow::Owned(out)
}

/// Prints `line` on standard error, escaped: the one way messages leave gridtrace.
pub fn say(line: impl Display) {
    eprintln!("{}", escaped(&line.to_string()));
}

/// Prints a report of several lines on standard output, each line escaped.
pub fn print_report(report: &str) {
    for line in report.lines() {
        println!("{}", escaped(line));
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn control_characters_become_visible_escapes() {
        assert!(matches!(escaped("plain 'name' ü"), Cow::Borrowed(_)));
        assert_eq!(
            escaped("mesh\u{1b}[2J\nerror: forged"),
            "mesh\\x1b[2J\\nerror: forged"
        );
        assert_eq!(
            escaped("\u{1b}]0;title\u{7}x.png"),
            "\\x1b]0;title\\x07x.png"
        );
        assert_eq!(escaped("a\u{9b}b\u{7f}"), "a\\x9bb\\x7f");
        assert_eq!(escaped("abc\u{202e}def"), "abc\\u{202e}def");
    }
}
