//! One thing wrong with a database, said so that a user can find and fix it.

use crate::model::Location;
use std::fmt;

#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord)]
pub enum Severity {
    /// Loads, but is probably not what the user meant.
    Warning,
    /// The record (or the file) cannot be used as it is.
    Error,
}

#[derive(Debug, Clone, PartialEq)]
pub struct Problem {
    pub severity: Severity,
    /// The file's path as the user gave it (e.g. `data/robots.xml`).
    pub file: String,
    pub location: Option<Location>,
    /// The element and, where it has one, its name: `<joint> in robot "housenka"`.
    pub element: String,
    pub message: String,
}

/// `text` on one line: control characters (a newline in a name, in a tag that the XML
/// parser quotes) written as escapes, so that a problem always prints as one line.
pub fn one_line(text: String) -> String {
    if !text.chars().any(char::is_control) {
        return text;
    }
    text.chars()
        .map(|c| {
            if c.is_control() {
                c.escape_default().to_string()
            } else {
                c.to_string()
            }
        })
        .collect()
}

impl Problem {
    pub fn error(file: &str, element: &str, message: impl Into<String>) -> Self {
        Self {
            severity: Severity::Error,
            file: file.to_string(),
            location: None,
            element: one_line(element.to_string()),
            message: one_line(message.into()),
        }
    }

    pub fn warning(file: &str, element: &str, message: impl Into<String>) -> Self {
        Self {
            severity: Severity::Warning,
            ..Self::error(file, element, message)
        }
    }

    pub fn at(mut self, location: Location) -> Self {
        if location.line > 0 {
            self.location = Some(location);
        }
        self
    }

    /// The same problem, its message continued.
    pub fn with_message_suffix(mut self, suffix: &str) -> Self {
        self.message.push_str(&one_line(suffix.to_string()));
        self
    }

    pub fn is_error(&self) -> bool {
        self.severity == Severity::Error
    }
}

impl fmt::Display for Problem {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{}", self.file)?;
        if let Some(l) = self.location {
            write!(f, ":{}:{}", l.line, l.column)?;
        }
        let severity = match self.severity {
            Severity::Error => "error",
            Severity::Warning => "warning",
        };
        write!(f, ": {severity}: {}: {}", self.element, self.message)
    }
}

/// The problems of each kind (errors, warnings) that one file lists; the rest are
/// counted. A file of a million unknown or broken elements is a million problems, which
/// no one reads and which took a hundred times the file's size in memory.
pub const LISTED_PER_FILE: usize = 100;

/// The problems of one file as it is read, each kind's list capped at [`LISTED_PER_FILE`].
#[derive(Debug, Default)]
pub(crate) struct FileProblems {
    listed: Vec<Problem>,
    /// Listed and unlisted counts: errors, warnings.
    errors: (usize, usize),
    warnings: (usize, usize),
}

impl FileProblems {
    pub(crate) fn push(&mut self, problem: Problem) {
        let (listed, unlisted) = if problem.is_error() {
            &mut self.errors
        } else {
            &mut self.warnings
        };
        if *listed < LISTED_PER_FILE {
            *listed += 1;
            self.listed.push(problem);
        } else {
            *unlisted += 1;
        }
    }

    /// Every problem pushed so far, listed or not.
    pub(crate) fn len(&self) -> usize {
        self.listed.len() + self.errors.1 + self.warnings.1
    }

    /// The listed problems, and one problem of each kind counting the rest, in `file`.
    pub(crate) fn into_vec(self, file: &str) -> Vec<Problem> {
        let mut list = self.listed;
        let more = |kind: &str, count: usize| {
            format!("{count} more {kind} not listed (the first {LISTED_PER_FILE} are)")
        };
        if self.errors.1 > 0 {
            list.push(Problem::error(file, "file", more("errors", self.errors.1)));
        }
        if self.warnings.1 > 0 {
            list.push(Problem::warning(
                file,
                "file",
                more("warnings", self.warnings.1),
            ));
        }
        list
    }
}
