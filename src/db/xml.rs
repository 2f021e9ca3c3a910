//! XML syntax only: a file's text becomes a small tree of elements with their attributes
//! and line/column, or one syntax problem. What the elements mean is `read.rs`'s business.

use super::problem::Problem;
use crate::model::Location;
use quick_xml::XmlVersion;
use quick_xml::events::{BytesStart, Event};

/// Deeper than this is not a database (the format nests three levels below the root).
pub const MAX_DEPTH: usize = 32;

#[derive(Debug, Clone, PartialEq)]
pub struct Element {
    pub name: String,
    pub attributes: Vec<(String, String)>,
    pub children: Vec<Element>,
    pub location: Location,
}

/// Line and column (1-based) of each byte offset of a text.
pub struct Lines {
    starts: Vec<usize>,
}

impl Lines {
    pub fn new(text: &str) -> Self {
        let starts = std::iter::once(0)
            .chain(text.match_indices('\n').map(|(i, _)| i + 1))
            .collect();
        Self { starts }
    }

    pub fn locate(&self, offset: usize) -> Location {
        let line = self.starts.partition_point(|&s| s <= offset);
        let start = self.starts[line.saturating_sub(1)];
        Location {
            line,
            column: offset - start + 1,
        }
    }
}

/// Decodes the bytes of a file as UTF-8 (a leading byte-order mark is skipped).
pub fn decode<'a>(bytes: &'a [u8], file: &str) -> Result<&'a str, Problem> {
    let bytes = bytes.strip_prefix(b"\xEF\xBB\xBF").unwrap_or(bytes);
    std::str::from_utf8(bytes).map_err(|e| {
        let valid = std::str::from_utf8(&bytes[..e.valid_up_to()]).unwrap_or_default();
        let location = Lines::new(valid).locate(valid.len());
        Problem::error(
            file,
            "file",
            format!("not valid UTF-8 (byte {} of the file)", e.valid_up_to() + 1),
        )
        .at(location)
    })
}

/// Parses `text` into its root element.
pub fn parse(text: &str, file: &str) -> Result<Element, Problem> {
    let lines = Lines::new(text);
    let mut reader = quick_xml::Reader::from_str(text);
    reader.config_mut().trim_text(true);
    let mut stack: Vec<Element> = Vec::new();
    let mut root: Option<Element> = None;
    loop {
        let before = reader.buffer_position() as usize;
        let tag_start = before + text[before.min(text.len())..].len()
            - text[before.min(text.len())..].trim_start().len();
        let location = lines.locate(tag_start);
        let event = reader.read_event().map_err(|e| {
            Problem::error(file, "file", format!("malformed XML: {e}"))
                .at(lines.locate(reader.error_position() as usize))
        })?;
        match event {
            Event::Start(start) | Event::Empty(start) if root.is_some() && stack.is_empty() => {
                let name = start.name().into_inner().to_string();
                return Err(Problem::error(
                    file,
                    &format!("<{name}>"),
                    "a second root element (a file has one)",
                )
                .at(location));
            }
            Event::Start(start) => {
                if stack.len() >= MAX_DEPTH {
                    return Err(Problem::error(
                        file,
                        "file",
                        format!("elements nested deeper than {MAX_DEPTH}"),
                    )
                    .at(location));
                }
                stack.push(element(&start, location, file)?);
            }
            Event::Empty(start) => {
                let done = element(&start, location, file)?;
                match stack.last_mut() {
                    Some(parent) => parent.children.push(done),
                    None => root = Some(done),
                }
            }
            Event::End(_) => {
                // quick-xml has checked that the name matches.
                let done = stack.pop().expect("an end tag follows its start");
                match stack.last_mut() {
                    Some(parent) => parent.children.push(done),
                    None => root = Some(done),
                }
            }
            Event::Text(t) => {
                let content = t.xml_content(XmlVersion::Implicit1_0);
                if !content.trim().is_empty() {
                    let inside = stack
                        .last()
                        .map_or("file".to_string(), |e| format!("<{}>", e.name));
                    return Err(Problem::error(
                        file,
                        &inside,
                        format!("unexpected text {:?}", clip(&content)),
                    )
                    .at(location));
                }
            }
            Event::CData(_) => {
                return Err(Problem::error(file, "file", "unexpected CDATA section").at(location));
            }
            Event::Eof => break,
            Event::Decl(_)
            | Event::Comment(_)
            | Event::PI(_)
            | Event::DocType(_)
            | Event::GeneralRef(_) => {}
        }
    }
    if let Some(open) = stack.last() {
        let end = lines.locate(text.len());
        return Err(Problem::error(
            file,
            &format!("<{}>", open.name),
            format!(
                "the file ends before <{}> (line {}) is closed: truncated?",
                open.name, open.location.line
            ),
        )
        .at(end));
    }
    root.ok_or_else(|| Problem::error(file, "file", "no root element (the file is empty)"))
}

fn element(start: &BytesStart, location: Location, file: &str) -> Result<Element, Problem> {
    let name = start.name().into_inner().to_string();
    let mut attributes: Vec<(String, String)> = Vec::new();
    for attribute in start.attributes() {
        let attribute = attribute.map_err(|e| {
            Problem::error(file, &format!("<{name}>"), format!("bad attribute: {e}")).at(location)
        })?;
        let key = attribute.key.into_inner().to_string();
        let value = attribute
            .normalized_value(XmlVersion::Implicit1_0)
            .map_err(|e| {
                Problem::error(file, &format!("<{name}>"), format!("attribute {key}: {e}"))
                    .at(location)
            })?;
        attributes.push((key, value.into_owned()));
    }
    Ok(Element {
        name,
        attributes,
        children: Vec::new(),
        location,
    })
}

/// A value shortened for a message.
pub fn clip(value: &str) -> String {
    const MAX: usize = 40;
    if value.chars().count() <= MAX {
        value.to_string()
    } else {
        let head: String = value.chars().take(MAX).collect();
        format!("{head}… ({} characters)", value.chars().count())
    }
}
