//! The small XML tree the Collada reader walks ([`super::collada`]): every element with its
//! attributes, text, children and the 1-based line of its start tag, parsed by `quick-xml`;
//! and the readers of the numbers and attributes Collada keeps in it. Errors are
//! [`Error::Parse`] naming the file, the line, the element and what was expected.

use quick_xml::events::{BytesStart, Event};

use super::collada::MAX_DEPTH;
use crate::error::{Error, Result};

pub(super) fn bad(name: &str, line: usize, message: impl Into<String>) -> Error {
    Error::Parse {
        source_name: name.into(),
        line,
        message: message.into(),
    }
}

/// One XML element, with the 1-based line its start tag is on.
#[derive(Debug, Default)]
pub(super) struct Element {
    pub(super) tag: String,
    pub(super) attrs: Vec<(String, String)>,
    pub(super) text: String,
    pub(super) children: Vec<Element>,
    pub(super) line: usize,
}

impl Element {
    pub(super) fn attr(&self, key: &str) -> Option<&str> {
        self.attrs
            .iter()
            .find(|(k, _)| k == key)
            .map(|(_, v)| v.as_str())
    }

    pub(super) fn child(&self, tag: &str) -> Option<&Element> {
        self.children.iter().find(|c| c.tag == tag)
    }

    pub(super) fn all<'a>(&'a self, tag: &'a str) -> impl Iterator<Item = &'a Element> + 'a {
        self.children.iter().filter(move |c| c.tag == tag)
    }

    /// `<tag id="…">` (or `<tag>`) for messages.
    pub(super) fn describe(&self) -> String {
        match self.attr("id") {
            Some(id) => format!("<{} id=\"{id}\">", self.tag),
            None => format!("<{}>", self.tag),
        }
    }
}

/// The 1-based line of byte `pos` of `text`.
pub(super) fn line_at(text: &str, pos: usize) -> usize {
    let end = pos.min(text.len());
    text.as_bytes()[..end]
        .iter()
        .filter(|&&b| b == b'\n')
        .count()
        + 1
}

pub(super) fn start_element(e: &BytesStart<'_>, line: usize, name: &str) -> Result<Element> {
    let tag = String::from_utf8_lossy(e.local_name().as_ref()).into_owned();
    let mut attrs = Vec::new();
    for a in e.attributes() {
        let a = a.map_err(|err| bad(name, line, format!("not well-formed XML: <{tag}>: {err}")))?;
        let key = String::from_utf8_lossy(a.key.local_name().as_ref()).into_owned();
        let value = a
            .unescape_value()
            .map_err(|err| {
                bad(
                    name,
                    line,
                    format!("not well-formed XML: <{tag} {key}>: {err}"),
                )
            })?
            .into_owned();
        attrs.push((key, value));
    }
    Ok(Element {
        tag,
        attrs,
        line,
        ..Element::default()
    })
}

/// The element tree of `text` (without a loop of recursion: the depth is checked first).
pub(super) fn parse_tree(text: &str, name: &str) -> Result<Element> {
    let mut reader = quick_xml::Reader::from_str(text);
    let mut stack: Vec<Element> = Vec::new();
    let mut root: Option<Element> = None;
    let (mut line, mut counted) = (1usize, 0usize);
    loop {
        let pos = (reader.buffer_position() as usize).min(text.len());
        let event = reader.read_event().map_err(|e| {
            let at = line_at(text, reader.error_position() as usize);
            bad(
                name,
                at,
                format!("not a Collada file: not well-formed XML: {e}"),
            )
        })?;
        let (start, empty) = match &event {
            Event::Start(e) => (e, false),
            Event::Empty(e) => (e, true),
            Event::Text(t) => {
                if let Some(top) = stack.last_mut() {
                    let s = t.decode().map_err(|e| bad(name, line, e.to_string()))?;
                    top.text.push_str(&s);
                }
                continue;
            }
            Event::CData(t) => {
                if let Some(top) = stack.last_mut() {
                    let s = t.decode().map_err(|e| bad(name, line, e.to_string()))?;
                    top.text.push_str(&s);
                }
                continue;
            }
            Event::End(_) => {
                if let Some(done) = stack.pop() {
                    attach(&mut stack, &mut root, done, name)?;
                }
                continue;
            }
            Event::Eof => break,
            _ => continue,
        };
        line += text.as_bytes()[counted..pos]
            .iter()
            .filter(|&&b| b == b'\n')
            .count();
        counted = pos;
        let el = start_element(start, line, name)?;
        if stack.len() >= MAX_DEPTH {
            return Err(bad(
                name,
                line,
                format!(
                    "<{}> is nested {} elements deep; at most {MAX_DEPTH} are read",
                    el.tag,
                    stack.len() + 1
                ),
            ));
        }
        if empty {
            attach(&mut stack, &mut root, el, name)?;
        } else {
            stack.push(el);
        }
    }
    if let Some(open) = stack.last() {
        return Err(bad(
            name,
            open.line,
            format!(
                "not a Collada file: <{}> is never closed (truncated?)",
                open.tag
            ),
        ));
    }
    root.ok_or_else(|| bad(name, 0, "not a Collada file: no XML element at all"))
}

pub(super) fn attach(
    stack: &mut [Element],
    root: &mut Option<Element>,
    el: Element,
    name: &str,
) -> Result<()> {
    if let Some(parent) = stack.last_mut() {
        parent.children.push(el);
    } else if root.is_none() {
        *root = Some(el);
    } else {
        return Err(bad(
            name,
            el.line,
            format!(
                "not a Collada file: a second root element <{}> after the first",
                el.tag
            ),
        ));
    }
    Ok(())
}

/// The finite numbers of `el`'s text, exactly `want` of them when given.
pub(super) fn floats(el: &Element, want: Option<usize>, name: &str) -> Result<Vec<f64>> {
    let mut out = Vec::new();
    for (k, w) in el.text.split_whitespace().enumerate() {
        let x = w
            .parse::<f64>()
            .ok()
            .filter(|x| x.is_finite())
            .ok_or_else(|| {
                bad(
                    name,
                    el.line,
                    format!(
                        "{}: number {k} is `{w}`, expected a finite number",
                        el.describe()
                    ),
                )
            })?;
        out.push(x);
    }
    if let Some(n) = want.filter(|&n| n != out.len()) {
        return Err(bad(
            name,
            el.line,
            format!(
                "{} holds {} numbers, expected {n}",
                el.describe(),
                out.len()
            ),
        ));
    }
    Ok(out)
}

/// The non-negative integers of `el`'s text.
pub(super) fn indices(el: &Element, name: &str) -> Result<Vec<usize>> {
    el.text
        .split_whitespace()
        .map(|w| {
            w.parse::<usize>().map_err(|_| {
                bad(
                    name,
                    el.line,
                    format!("<{}>: `{w}` is not a non-negative integer index", el.tag),
                )
            })
        })
        .collect()
}

/// Attribute `key` of `el` as a non-negative integer, `default` when absent.
pub(super) fn count_attr(
    el: &Element,
    key: &str,
    default: Option<usize>,
    name: &str,
) -> Result<usize> {
    match (el.attr(key), default) {
        (Some(v), _) => v.trim().parse::<usize>().map_err(|_| {
            bad(
                name,
                el.line,
                format!(
                    "{}: {key}=\"{v}\" is not a non-negative integer",
                    el.describe()
                ),
            )
        }),
        (None, Some(d)) => Ok(d),
        (None, None) => Err(bad(
            name,
            el.line,
            format!("{} has no `{key}` attribute", el.describe()),
        )),
    }
}

/// The element `url` (`#id`) names among `candidates`.
pub(super) fn by_url<'a>(candidates: &[&'a Element], url: &str) -> Option<&'a Element> {
    let id = url.strip_prefix('#')?;
    candidates
        .iter()
        .copied()
        .find(|e| e.attr("id") == Some(id))
}
