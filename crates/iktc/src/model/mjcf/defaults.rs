//! `<default>` classes: each element's attributes, then its class's, then the class's
//! ancestors'.

use std::collections::HashMap;

use super::xml::El;
use crate::error::Result;

/// The name of the top-level default class.
pub(crate) const MAIN: &str = "main";

/// The tags that share one actuator default in a class (MuJoCo's shortcuts of `<general>`).
const ACTUATOR_TAGS: &[&str] = &[
    "general",
    "motor",
    "position",
    "velocity",
    "intvelocity",
    "damper",
    "cylinder",
    "muscle",
    "adhesion",
];

/// The key a default is stored under for an element tag: the actuator shortcuts share one.
fn key(tag: &str) -> &str {
    if ACTUATOR_TAGS.contains(&tag) {
        "actuator"
    } else {
        tag
    }
}

/// Attributes by class, then by element tag, each class holding its ancestors' attributes
/// that it does not set itself.
#[derive(Debug, Default)]
pub(crate) struct Defaults {
    classes: HashMap<String, HashMap<String, Vec<(String, String)>>>,
}

impl Defaults {
    /// The classes of every `<default>` directly under `root` (the `<mujoco>` element).
    ///
    /// Errors: a nested `<default>` without `class`, or a class defined twice.
    pub fn of(root: &El) -> Result<Defaults> {
        let mut d = Defaults::default();
        d.classes.insert(MAIN.into(), HashMap::new());
        for top in root.elements("default") {
            let name = top.attr("class").unwrap_or(MAIN);
            d.class(top, name, None)?;
        }
        Ok(d)
    }

    /// Reads the class `name` written as `el`, below the class `parent`.
    fn class(&mut self, el: &El, name: &str, parent: Option<&str>) -> Result<()> {
        let mut own: HashMap<String, Vec<(String, String)>> = match parent {
            Some(p) => self.classes.get(p).cloned().unwrap_or_default(),
            None => self.classes.get(name).cloned().unwrap_or_default(),
        };
        if parent.is_some() && self.classes.contains_key(name) {
            return Err(el.error(format!("default class `{name}` is defined twice")));
        }
        for c in el.children.iter().filter(|c| c.tag != "default") {
            let entry = own.entry(key(&c.tag).to_string()).or_default();
            for (k, v) in &c.attrs {
                match entry.iter_mut().find(|(ek, _)| ek == k) {
                    Some(e) => e.1.clone_from(v),
                    None => entry.push((k.clone(), v.clone())),
                }
            }
        }
        self.classes.insert(name.to_string(), own);
        for child in el.elements("default") {
            let Some(sub) = child.attr("class") else {
                return Err(child.error("a nested <default> needs a `class` name"));
            };
            self.class(child, sub, Some(name))?;
        }
        Ok(())
    }

    /// Whether the class `name` exists.
    pub fn has(&self, name: &str) -> bool {
        self.classes.contains_key(name)
    }

    /// The names of the classes, sorted (for messages).
    pub fn names(&self) -> Vec<String> {
        let mut v: Vec<String> = self.classes.keys().cloned().collect();
        v.sort();
        v
    }

    /// The attribute `attr` of an element with tag `tag` in class `class`.
    pub fn get(&self, class: &str, tag: &str, attr: &str) -> Option<&str> {
        self.classes
            .get(class)?
            .get(key(tag))?
            .iter()
            .find(|(k, _)| k == attr)
            .map(|(_, v)| v.as_str())
    }
}

/// An element seen through its class: [`Attrs::get`] returns the element's own attribute,
/// else its class's.
#[derive(Clone, Copy)]
pub(crate) struct Attrs<'a> {
    pub el: &'a El,
    pub class: &'a str,
    pub defaults: &'a Defaults,
}

impl<'a> Attrs<'a> {
    /// `el` in its class: its own `class` attribute, else `childclass` (the innermost
    /// `childclass` of the bodies and frames around it, itself included).
    ///
    /// Errors: a class that no `<default>` defines.
    pub fn new(el: &'a El, childclass: &'a str, defaults: &'a Defaults) -> Result<Attrs<'a>> {
        let class = el.attr("class").unwrap_or(childclass);
        if !defaults.has(class) {
            return Err(el.error(format!(
                "class `{class}` is not defined by any <default>; classes are {}",
                crate::error::name_list(&defaults.names())
            )));
        }
        Ok(Attrs {
            el,
            class,
            defaults,
        })
    }

    /// The attribute `attr`: the element's, else its class's.
    pub fn get(&self, attr: &str) -> Option<&'a str> {
        self.el
            .attr(attr)
            .or_else(|| self.defaults.get(self.class, &self.el.tag, attr))
    }
}
