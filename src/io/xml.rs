//! A small XML tree with source positions, for the URDF and MJCF readers.
//!
//! Entry points: [`parse_file`], [`parse_bytes`] → [`Element`]. Every element remembers the file
//! and the 1-based line of its start tag, so a finding can point at it; a parse error names
//! `file:line`.

use crate::error::{Error, Result};
use quick_xml::events::{BytesStart, Event};
use std::path::{Path, PathBuf};
use std::sync::Arc;

/// One element: its name, attributes in file order, children, and where it starts.
#[derive(Clone, Debug)]
pub struct Element {
    pub name: String,
    pub attrs: Vec<(String, String)>,
    pub children: Vec<Element>,
    pub file: Arc<PathBuf>,
    pub line: usize,
}

impl Element {
    /// The value of attribute `key`.
    pub fn attr(&self, key: &str) -> Option<&str> {
        self.attrs
            .iter()
            .find(|(k, _)| k == key)
            .map(|(_, v)| v.as_str())
    }
    /// The first child named `name`.
    pub fn child(&self, name: &str) -> Option<&Element> {
        self.children.iter().find(|c| c.name == name)
    }
    /// Every child named `name`.
    pub fn children_named<'a>(&'a self, name: &'a str) -> impl Iterator<Item = &'a Element> + 'a {
        self.children.iter().filter(move |c| c.name == name)
    }
    /// `file:line` of this element.
    pub fn at(&self) -> String {
        format!("{}:{}", self.file.display(), self.line)
    }
    /// An input error naming this element's file and line.
    pub fn error(&self, message: impl AsRef<str>) -> Error {
        Error::input(
            &*self.file,
            format!("line {}: <{}>: {}", self.line, self.name, message.as_ref()),
        )
    }
}

/// Read and parse an XML file (size-limited like every other input).
pub fn parse_file(path: &Path, limits: &crate::io::Limits) -> Result<Element> {
    let bytes = crate::io::read_file(path, limits)?;
    parse_bytes(path, &bytes)
}

/// Line (1-based) of a byte offset.
fn line_of(bytes: &[u8], offset: usize) -> usize {
    1 + bytes[..offset.min(bytes.len())]
        .iter()
        .filter(|&&b| b == b'\n')
        .count()
}

/// Parse XML bytes into the tree of its root element.
pub fn parse_bytes(path: &Path, bytes: &[u8]) -> Result<Element> {
    let file = Arc::new(path.to_path_buf());
    let mut reader = quick_xml::Reader::from_reader(bytes);
    reader.config_mut().check_end_names = true;
    let mut stack: Vec<Element> = Vec::new();
    let mut root: Option<Element> = None;
    // Lines counted incrementally: offsets only grow.
    let (mut counted_to, mut line) = (0usize, 1usize);
    let mut line_at = |off: usize| {
        let off = off.min(bytes.len());
        if off >= counted_to {
            line += bytes[counted_to..off]
                .iter()
                .filter(|&&b| b == b'\n')
                .count();
            counted_to = off;
        }
        line
    };
    let err_at = |off: u64, msg: String| {
        Error::input(
            path,
            format!("line {}: invalid XML: {msg}", line_of(bytes, off as usize)),
        )
    };
    loop {
        let before = reader.buffer_position() as usize;
        let ev = reader
            .read_event()
            .map_err(|e| err_at(reader.error_position(), e.to_string()))?;
        // The event starts at the first '<' after the previous one ended.
        let start = bytes[before..]
            .iter()
            .position(|&b| b == b'<')
            .map_or(before, |k| before + k);
        match ev {
            Event::Start(e) => {
                let el = element(&e, &file, line_at(start), path, bytes, start)?;
                stack.push(el);
            }
            Event::Empty(e) => {
                let el = element(&e, &file, line_at(start), path, bytes, start)?;
                match stack.last_mut() {
                    Some(p) => p.children.push(el),
                    None if root.is_none() => root = Some(el),
                    None => return Err(err_at(start as u64, "more than one root element".into())),
                }
            }
            Event::End(_) => {
                let el = stack
                    .pop()
                    .ok_or_else(|| err_at(start as u64, "unexpected end tag".into()))?;
                match stack.last_mut() {
                    Some(p) => p.children.push(el),
                    None if root.is_none() => root = Some(el),
                    None => return Err(err_at(start as u64, "more than one root element".into())),
                }
            }
            Event::Eof => break,
            _ => {}
        }
    }
    if let Some(open) = stack.last() {
        return Err(Error::input(
            path,
            format!(
                "line {}: invalid XML: <{}> is never closed",
                open.line, open.name
            ),
        ));
    }
    root.ok_or_else(|| Error::input(path, "invalid XML: no root element"))
}

fn element(
    e: &BytesStart,
    file: &Arc<PathBuf>,
    line: usize,
    path: &Path,
    bytes: &[u8],
    start: usize,
) -> Result<Element> {
    let name = String::from_utf8_lossy(e.name().as_ref()).into_owned();
    let mut attrs = Vec::new();
    for a in e.attributes() {
        let a = a.map_err(|err| {
            Error::input(
                path,
                format!(
                    "line {}: invalid XML attribute in <{name}>: {err}",
                    line_of(bytes, start)
                ),
            )
        })?;
        let key = String::from_utf8_lossy(a.key.as_ref()).into_owned();
        let value = a
            .unescape_value()
            .map_err(|err| {
                Error::input(
                    path,
                    format!("line {line}: invalid XML attribute {key:?}: {err}"),
                )
            })?
            .into_owned();
        attrs.push((key, value));
    }
    Ok(Element {
        name,
        attrs,
        children: Vec::new(),
        file: file.clone(),
        line,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn lines_and_errors_name_the_line() {
        let x = b"<?xml version=\"1.0\"?>\n<a>\n  <b x=\"1\"/>\n\n  <c>\n    <d/>\n  </c>\n</a>\n";
        let r = parse_bytes(Path::new("t.xml"), x).unwrap();
        assert_eq!(r.line, 2);
        assert_eq!(r.child("b").unwrap().line, 3);
        assert_eq!(r.child("b").unwrap().attr("x"), Some("1"));
        assert_eq!(r.child("c").unwrap().children[0].line, 6);
        let e = parse_bytes(Path::new("t.xml"), b"<a>\n<b>\n</a>\n").unwrap_err();
        assert!(e.to_string().contains("t.xml: line 3"), "{e}");
    }
}
