//! XML syntax only: a file's text becomes a small tree of elements with their attributes
//! and line/column, or one syntax problem. What the elements mean is `read.rs`'s business.

use super::problem::{FileProblems, Problem, one_line};
use crate::model::Location;
use quick_xml::XmlVersion;
use quick_xml::events::{BytesStart, Event};

/// Deeper than this is not a database (the format nests three levels below the root).
pub const MAX_DEPTH: usize = 32;

/// More elements than this is not a database: 50,000 bodies of four vertices are 250,000.
/// It keeps a file of millions of tiny elements (`<x/>`, 4 bytes each, 88 in the tree)
/// from taking gigabytes before it is found to be nonsense.
pub const MAX_ELEMENTS: usize = 1 << 22;

/// An element as the reader needs it. Kept small (88 bytes, its name shared with every
/// element of that name): a file of millions of tiny elements is a tree of millions.
#[derive(Debug, Clone, PartialEq)]
pub struct Element {
    pub name: Name,
    pub attributes: Vec<(String, String)>,
    pub children: Vec<Element>,
    pub location: Location,
    /// For a record (a child of the root): its text in the file, from its tag's `<` to
    /// the end of its end tag, so that saving can write an unchanged record as it was.
    pub span: Option<Box<std::ops::Range<usize>>>,
}

/// An element's name, one allocation shared by every element of that name in a file.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Name(std::sync::Arc<str>);

impl std::ops::Deref for Name {
    type Target = str;
    fn deref(&self) -> &str {
        &self.0
    }
}

impl std::fmt::Display for Name {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(&self.0)
    }
}

impl PartialEq<&str> for Name {
    fn eq(&self, other: &&str) -> bool {
        &*self.0 == *other
    }
}

/// The names met in one file, each allocated once.
#[derive(Default)]
struct Names(std::collections::HashMap<String, Name>);

impl Names {
    fn of(&mut self, name: &str) -> Name {
        if let Some(known) = self.0.get(name) {
            return known.clone();
        }
        let new = Name(std::sync::Arc::from(name));
        self.0.insert(name.to_string(), new.clone());
        new
    }
}

/// Line and column (1-based) of each byte offset of a text.
pub struct Lines {
    starts: Vec<usize>,
}

impl Lines {
    /// Lines end at `\n`, `\r\n` or a lone `\r` (old Mac files).
    pub fn new(text: &str) -> Self {
        let bytes = text.as_bytes();
        let ends = bytes
            .iter()
            .enumerate()
            .filter(|&(i, &b)| b == b'\n' || (b == b'\r' && bytes.get(i + 1) != Some(&b'\n')));
        let starts = std::iter::once(0).chain(ends.map(|(i, _)| i + 1)).collect();
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

/// A file's text: UTF-8 as it is, or decoded from the encoding its byte-order mark or XML
/// declaration names (the thesis's application ran on Czech Windows: `windows-1250`),
/// with a warning that saving writes it as UTF-8.
pub struct Decoded<'a> {
    pub text: std::borrow::Cow<'a, str>,
    pub warning: Option<Problem>,
}

/// Decodes the bytes of a file: a byte-order mark (UTF-8, UTF-16) or the declaration's
/// `encoding` says how; without either, UTF-8.
pub fn decode<'a>(bytes: &'a [u8], file: &str) -> Result<Decoded<'a>, Problem> {
    let (encoding, bom) = match encoding_rs::Encoding::for_bom(bytes) {
        Some((encoding, bom)) => (encoding, bom),
        None => (declared_encoding(bytes).unwrap_or(encoding_rs::UTF_8), 0),
    };
    // A declaration read in ASCII cannot be UTF-16 (whose ASCII has a zero byte in every
    // character, and which begins with a byte-order mark): the file is read as UTF-8.
    let utf16 = [encoding_rs::UTF_16LE, encoding_rs::UTF_16BE];
    let (encoding, mislabelled) = if bom == 0 && utf16.contains(&encoding) {
        (encoding_rs::UTF_8, Some(encoding.name()))
    } else {
        (encoding, None)
    };
    let body = &bytes[bom..];
    if encoding == encoding_rs::UTF_8 {
        let text = std::str::from_utf8(body).map_err(|e| {
            let valid = std::str::from_utf8(&body[..e.valid_up_to()]).unwrap_or_default();
            let location = Lines::new(valid).locate(valid.len());
            Problem::error(
                file,
                "file",
                format!(
                    "not valid UTF-8 (byte {} of the file)",
                    bom + e.valid_up_to() + 1
                ),
            )
            .at(location)
        })?;
        let warning = mislabelled.map(|declared| {
            Problem::warning(
                file,
                "file",
                format!(
                    "declares {declared} but is written in ASCII, with no byte-order mark: read as UTF-8"
                ),
            )
        });
        return Ok(Decoded {
            text: std::borrow::Cow::Borrowed(text),
            warning,
        });
    }
    let (text, had_errors) = encoding.decode_without_bom_handling(body);
    if had_errors {
        return Err(Problem::error(
            file,
            "file",
            format!("not valid {} (the encoding it declares)", encoding.name()),
        ));
    }
    let warning = Problem::warning(
        file,
        "file",
        format!(
            "encoded as {}: read as such, and saved as UTF-8",
            encoding.name()
        ),
    );
    Ok(Decoded {
        text: std::borrow::Cow::Owned(text.into_owned()),
        warning: Some(warning),
    })
}

/// The encoding an XML declaration at the start of `bytes` names, if it names one
/// encoding_rs knows. (The declaration is ASCII in every encoding a database may use
/// without a byte-order mark.)
fn declared_encoding(bytes: &[u8]) -> Option<&'static encoding_rs::Encoding> {
    let head = &bytes[..bytes.len().min(256)];
    let head = std::str::from_utf8(head)
        .or_else(|e| std::str::from_utf8(&head[..e.valid_up_to()]))
        .ok()?;
    let declaration = head.strip_prefix("<?xml")?;
    let declaration = &declaration[..declaration.find("?>")?];
    let at = declaration.find("encoding")?;
    let rest = declaration[at + "encoding".len()..].trim_start();
    let rest = rest.strip_prefix('=')?.trim_start();
    let quote = rest.chars().next().filter(|q| *q == '"' || *q == '\'')?;
    let label = &rest[1..][..rest[1..].find(quote)?];
    encoding_rs::Encoding::for_label(label.trim().as_bytes())
}

/// What parsing a file gave: its root and the records skipped for their syntax.
pub struct Parsed {
    pub root: Element,
    /// One error per record skipped, and warnings for what was ignored (stray text).
    pub problems: Vec<Problem>,
    pub skipped: bool,
}

/// A syntax error, and the record (a child of the root) it lies in: where the record's
/// tag starts, and its name.
struct SyntaxError {
    problem: Box<Problem>,
    record: Option<(usize, String)>,
}

/// Records skipped for their syntax before a file is given up as unreadable: each one
/// reads the file again.
const MAX_SKIPPED_RECORDS: usize = 32;

/// Parses `text` into its root element, record by record: a syntax error inside one of
/// the root's children (a duplicated attribute, an unknown entity, a broken tag) skips
/// that record with an error naming it, and the rest of the file still loads; a file cut
/// off after its last whole record loads those. An error outside every record (no root,
/// two roots) loses the file, with the problems found until then.
pub fn parse(text: &str, file: &str) -> Result<Parsed, Vec<Problem>> {
    let mut text = std::borrow::Cow::Borrowed(text);
    let mut problems = Vec::new();
    let mut skipped = false;
    loop {
        // Each attempt reads the file anew: only the last one's warnings stand.
        let mut warnings = FileProblems::default();
        match parse_once(&text, file, &mut warnings) {
            Ok((root, truncated)) => {
                problems.extend(warnings.into_vec(file));
                problems.sort_by_key(|p| p.location.map(|l| (l.line, l.column)));
                return Ok(Parsed {
                    root,
                    problems,
                    skipped: skipped || truncated,
                });
            }
            Err(SyntaxError {
                problem,
                record: Some(_),
            }) if problems.len() >= MAX_SKIPPED_RECORDS => {
                problems.push((*problem).with_message_suffix(&format!(
                    "; more than {MAX_SKIPPED_RECORDS} records are broken: the file is not read"
                )));
                return Err(problems);
            }
            Err(SyntaxError {
                problem,
                record: Some((start, name)),
            }) => {
                problems.push((*problem).with_message_suffix("; the record is skipped"));
                skipped = true;
                // Blanked rather than cut, so that every later line keeps its number.
                let end = next_record(&text, start, &name);
                let mut bytes = text.into_owned().into_bytes();
                for b in &mut bytes[start..end] {
                    if *b != b'\n' && *b != b'\r' {
                        *b = b' ';
                    }
                }
                text = std::borrow::Cow::Owned(
                    String::from_utf8(bytes).expect("blanked with ASCII spaces"),
                );
            }
            Err(SyntaxError { problem, .. }) => {
                problems.push(*problem);
                return Err(problems);
            }
        }
    }
}

/// Where the record that starts at `start` ends for skipping it: after its own end tag
/// if that comes before the next tag of the same name; else at that next tag, or the
/// root's end tag, or the end of the text.
fn next_record(text: &str, start: usize, name: &str) -> usize {
    let after = start + 1;
    let open = format!("<{name}");
    let next = text[after..]
        .match_indices(&open)
        .map(|(i, _)| after + i)
        .find(|&i| {
            let follows = text[i + open.len()..].chars().next();
            follows.is_none_or(|c| c.is_whitespace() || c == '>' || c == '/')
        });
    let own_end = format!("</{name}>");
    let closed = text[after..]
        .find(&own_end)
        .map(|i| after + i + own_end.len())
        .filter(|&end| next.is_none_or(|n| end <= n));
    let root_end = text[after..].rfind("</").map(|i| after + i);
    closed
        .or(next.map(|n| root_end.map_or(n, |r| n.min(r))))
        .or(root_end)
        .unwrap_or(text.len())
}

/// One reading of `text`: its root, and whether the file was cut off after its last whole
/// record (its root never closed: reported in `problems`).
fn parse_once(
    text: &str,
    file: &str,
    problems: &mut FileProblems,
) -> Result<(Element, bool), SyntaxError> {
    let lines = Lines::new(text);
    let mut reader = quick_xml::Reader::from_str(text);
    reader.config_mut().trim_text(true);
    let mut stack: Vec<Element> = Vec::new();
    let mut root: Option<Element> = None;
    let mut names = Names::default();
    let mut elements = 0usize;
    // The record (a child of the root) being read: where its tag starts, and its name.
    let mut record: Option<(usize, String)> = None;
    // Whether the open record holds something ignored: then it has no span, so that saving
    // writes it afresh without what was ignored, as the warning says.
    let mut record_has_ignored = false;
    let fail = |problem: Problem, record: &Option<(usize, String)>| SyntaxError {
        problem: Box::new(problem),
        record: record.clone(),
    };
    loop {
        let before = reader.buffer_position() as usize;
        let tag_start = before + text[before.min(text.len())..].len()
            - text[before.min(text.len())..].trim_start().len();
        let location = lines.locate(tag_start);
        let event = match reader.read_event() {
            Ok(event) => event,
            Err(e) => {
                let at = lines.locate(reader.error_position() as usize);
                let problem = Problem::error(file, "file", format!("malformed XML: {e}")).at(at);
                return Err(fail(problem, &record));
            }
        };
        // A tag of the root's own children starts a record.
        let starts_record = |stack: &Vec<Element>| stack.len() == 1;
        if matches!(event, Event::Start(_) | Event::Empty(_)) {
            elements += 1;
            if elements > MAX_ELEMENTS {
                let message = format!("more than {MAX_ELEMENTS} elements: not a database");
                let problem = Problem::error(file, "file", message).at(location);
                return Err(fail(problem, &None));
            }
        }
        match event {
            Event::Start(start) | Event::Empty(start) if root.is_some() && stack.is_empty() => {
                let name = start.name().into_inner().to_string();
                let problem = Problem::error(
                    file,
                    &format!("<{name}>"),
                    "a second root element (a file has one)",
                )
                .at(location);
                return Err(fail(problem, &None));
            }
            Event::Start(start) => {
                if starts_record(&stack) {
                    record = Some((tag_start, tag_name(&start)));
                    record_has_ignored = false;
                }
                if stack.len() >= MAX_DEPTH {
                    let problem = Problem::error(
                        file,
                        "file",
                        format!("elements nested deeper than {MAX_DEPTH}"),
                    )
                    .at(location);
                    return Err(fail(problem, &record));
                }
                let element =
                    element(&start, location, file, &mut names).map_err(|p| fail(p, &record))?;
                stack.push(element);
            }
            Event::Empty(start) => {
                if starts_record(&stack) {
                    record = Some((tag_start, tag_name(&start)));
                }
                let mut done =
                    element(&start, location, file, &mut names).map_err(|p| fail(p, &record))?;
                if stack.len() == 1 {
                    done.span = Some(Box::new(tag_start..reader.buffer_position() as usize));
                }
                match stack.last_mut() {
                    Some(parent) => parent.children.push(done),
                    None => root = Some(done),
                }
                if stack.len() == 1 {
                    record = None;
                }
            }
            Event::End(_) => {
                // quick-xml has checked that the name matches.
                let mut done = stack.pop().expect("an end tag follows its start");
                if stack.len() == 1
                    && let Some((start, _)) = &record
                    && !record_has_ignored
                {
                    done.span = Some(Box::new(*start..reader.buffer_position() as usize));
                }
                match stack.last_mut() {
                    Some(parent) => parent.children.push(done),
                    None => root = Some(done),
                }
                if stack.len() == 1 {
                    record = None;
                }
            }
            Event::Text(t) => {
                let content = t.xml_content(XmlVersion::Implicit1_0);
                if !content.trim().is_empty() {
                    record_has_ignored |= stack.len() >= 2;
                    problems.push(ignored(
                        file,
                        &stack,
                        format!("text \"{}\"", clip(&content)),
                        location,
                    ));
                }
            }
            Event::CData(_) => {
                record_has_ignored |= stack.len() >= 2;
                problems.push(ignored(file, &stack, "CDATA section".into(), location));
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
        let problem = Problem::error(
            file,
            &format!("<{}>", open.name),
            format!(
                "the file ends before <{}> (line {}) is closed: truncated?",
                open.name, open.location.line
            ),
        )
        .at(end);
        if stack.len() >= 2 {
            // A truncated record is skipped like any broken one.
            return Err(fail(problem, &record));
        }
        // The root alone is open: its whole records load.
        problems.push(problem);
        let root = stack.pop().expect("the root is open");
        return Ok((root, true));
    }
    match root {
        Some(root) => Ok((root, false)),
        None => Err(fail(
            Problem::error(file, "file", no_root_because(text)),
            &None,
        )),
    }
}

/// Why a file has no root element, in terms of what it holds.
fn no_root_because(text: &str) -> String {
    let content = text.trim_start_matches('\u{feff}').trim();
    if content.is_empty() {
        return "no root element (the file is empty)".to_string();
    }
    let what = if content.starts_with('{') || content.starts_with('[') {
        "JSON or other text, not XML"
    } else if content.starts_with('<') {
        "markup but no element (only a declaration, comments or instructions)"
    } else {
        "text, not XML"
    };
    let beginning: String = content.chars().take(30).collect();
    format!(
        "no root element: the file holds {what} (it begins \"{}\")",
        clip(&beginning)
    )
}

fn tag_name(start: &BytesStart) -> String {
    start.name().into_inner().to_string()
}

/// A warning for something the reader ignores (and saving does not keep).
fn ignored(file: &str, stack: &[Element], what: String, location: Location) -> Problem {
    let inside = stack
        .last()
        .map_or("file".to_string(), |e| format!("<{}>", e.name));
    Problem::warning(
        file,
        &inside,
        format!("unexpected {what}, ignored (and not kept when this file is saved)"),
    )
    .at(location)
}

fn element(
    start: &BytesStart,
    location: Location,
    file: &str,
    names: &mut Names,
) -> Result<Element, Problem> {
    let name = names.of(start.name().into_inner());
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
        span: None,
    })
}

/// A value shortened for a message, its control characters escaped (`\n`, `\u{1b}`):
/// a message is one line, and a name from a file must not move the terminal's cursor.
pub fn clip(value: &str) -> String {
    const MAX: usize = 40;
    if value.chars().count() <= MAX {
        one_line(value.to_string())
    } else {
        let head: String = value.chars().take(MAX).collect();
        format!("{}… ({} characters)", one_line(head), value.chars().count())
    }
}

#[cfg(test)]
mod size {
    /// The element's size, which a file of tiny elements multiplies by millions.
    #[test]
    fn an_element_is_88_bytes() {
        assert_eq!(std::mem::size_of::<super::Element>(), 88);
    }
}
