//! The small XML tree the Collada reader walks ([`super::collada`]): every element with its
//! attributes, text, children and the 1-based line of its start tag, parsed by `roxmltree`;
//! and the readers of the numbers and attributes Collada keeps in it. Errors are
//! [`Error::Parse`] naming the file, the line, the element and what was expected.

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

/// The element tree of `text`, parsed by `roxmltree` and walked in document order without
/// recursion (the depth is checked as each element opens). A document type declaration is allowed (its
/// entities are expanded under `roxmltree`'s bounds); text and CDATA directly inside an
/// element are joined into its `text`.
pub(super) fn parse_tree(text: &str, name: &str) -> Result<Element> {
    if !text.contains('<') {
        return Err(bad(name, 0, "not a Collada file: no XML element at all"));
    }
    let options = roxmltree::ParsingOptions {
        allow_dtd: true,
        ..roxmltree::ParsingOptions::default()
    };
    let doc = roxmltree::Document::parse_with_options(text, options)
        .map_err(|e| xml_error(&e, text, name))?;
    // The open elements with their node ids, outermost first; nodes come in document order
    // (pre-order), so an element closes when a node that is not inside it comes.
    let mut stack: Vec<(roxmltree::NodeId, Element)> = Vec::new();
    let mut root: Option<Element> = None;
    let close_until = |stack: &mut Vec<(roxmltree::NodeId, Element)>,
                       root: &mut Option<Element>,
                       parent: Option<roxmltree::NodeId>| {
        while stack.last().is_some_and(|(id, _)| Some(*id) != parent) {
            if let Some((_, done)) = stack.pop() {
                match stack.last_mut() {
                    Some((_, up)) => up.children.push(done),
                    None => *root = Some(done),
                }
            }
        }
    };
    // Elements open in document order: their lines are counted on from the previous one.
    let (mut line, mut counted) = (1usize, 0usize);
    for node in doc.root_element().descendants() {
        if node.is_element() {
            close_until(&mut stack, &mut root, node.parent().map(|p| p.id()));
            let pos = node.range().start.min(text.len());
            line += text.as_bytes()[counted.min(pos)..pos]
                .iter()
                .filter(|&&b| b == b'\n')
                .count();
            counted = counted.max(pos);
            let el = Element {
                tag: node.tag_name().name().to_string(),
                attrs: node
                    .attributes()
                    .map(|a| (a.name().to_string(), a.value().to_string()))
                    .collect(),
                line,
                ..Element::default()
            };
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
            stack.push((node.id(), el));
        } else if let Some(t) = node.text().filter(|_| node.is_text()) {
            close_until(&mut stack, &mut root, node.parent().map(|p| p.id()));
            if let Some((_, top)) = stack.last_mut() {
                top.text.push_str(t);
            }
        }
    }
    close_until(&mut stack, &mut root, None);
    root.ok_or_else(|| bad(name, 0, "not a Collada file: no XML element at all"))
}

/// A parse error of `roxmltree` as an [`Error::Parse`] at its line.
fn xml_error(e: &roxmltree::Error, text: &str, name: &str) -> Error {
    use roxmltree::Error as X;
    match e {
        X::NoRootNode => bad(name, 0, "not a Collada file: no XML element at all"),
        X::UnclosedRootNode | X::UnexpectedEndOfStream => bad(
            name,
            line_at(text, text.len()),
            "not a Collada file: an element is never closed (truncated?)",
        ),
        _ => bad(
            name,
            e.pos().row as usize,
            format!("not a Collada file: not well-formed XML: {e}"),
        ),
    }
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
