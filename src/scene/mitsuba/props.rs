//! A plugin's parameters, read the way Mitsuba's `Properties` are: each
//! reader asks for the parameters its plugin knows, by name and type, and
//! whatever it did not ask for is an error at its place ([`Plugin::finish`]),
//! as Mitsuba reports unqueried properties. References (`<ref id>`) are
//! looked through.

use super::spectrum::{self, Use};
use super::xml::{error, Element};
use super::Loc;
use crate::math::Color;
use crate::scene::file::SceneError;
use glam::{DAffine3, DMat3, DVec3};
use std::cell::RefCell;
use std::collections::BTreeMap;

/// The tags that hold a parameter's value (the rest are objects).
const VALUE_TAGS: [&str; 10] =
    ["float", "integer", "boolean", "string", "rgb", "spectrum", "point", "vector", "transform", "color"];

/// Every element with an `id`, by id (what `<ref>` names).
pub type Ids<'a> = BTreeMap<&'a str, &'a Element>;

pub fn collect_ids<'a>(root: &'a Element, ids: &mut Ids<'a>) -> Result<(), SceneError> {
    for c in &root.children {
        if let Some(id) = c.attr("id") {
            if c.tag != "ref" && !VALUE_TAGS.contains(&c.tag.as_str()) && ids.insert(id, c).is_some() {
                return Err(error(&c.loc, format!("{}.id", c.tag), format!("the id '{id}' is used twice")));
            }
        }
        collect_ids(c, ids)?;
    }
    Ok(())
}

/// A plugin instance: its element, and which of its children were read.
pub struct Plugin<'a> {
    pub el: &'a Element,
    pub kind: &'a str,
    ids: &'a Ids<'a>,
    used: RefCell<Vec<bool>>,
}

/// A colour or a texture, where Mitsuba allows either.
pub enum Value<'a> {
    Color(Color),
    Texture(Plugin<'a>),
}

impl<'a> Plugin<'a> {
    pub fn new(el: &'a Element, ids: &'a Ids<'a>) -> Result<Self, SceneError> {
        let kind = el.attr("type").ok_or_else(|| error(&el.loc, &el.tag, format!("a <{}> needs a type", el.tag)))?;
        for (k, _) in &el.attrs {
            if !matches!(k.as_str(), "type" | "id" | "name") {
                return Err(error(&el.loc, format!("{}.{k}", el.tag), format!("unknown attribute '{k}'")));
            }
        }
        Ok(Plugin { el, kind, ids, used: RefCell::new(vec![false; el.children.len()]) })
    }

    pub fn loc(&self) -> &Loc {
        &self.el.loc
    }

    /// The error `message` about parameter `name` of this plugin, at `loc`.
    pub fn fail(&self, loc: &Loc, name: &str, message: impl Into<String>) -> SceneError {
        error(loc, format!("{} '{}'.{name}", self.el.tag, self.kind), message)
    }

    /// The plugin itself is refused (or a combination of its parameters).
    pub fn refuse(&self, message: impl Into<String>) -> SceneError {
        error(&self.el.loc, format!("{} '{}'", self.el.tag, self.kind), message)
    }

    /// Looks through `<ref>`: the element a child stands for.
    fn resolve(&self, c: &'a Element) -> Result<&'a Element, SceneError> {
        if c.tag != "ref" {
            return Ok(c);
        }
        let id = c.attr("id").ok_or_else(|| error(&c.loc, "ref", "a <ref> needs an id"))?;
        self.ids.get(id).copied().ok_or_else(|| error(&c.loc, "ref.id", format!("no object has the id '{id}'")))
    }

    /// The child named `name` (a parameter or a named object), marked read.
    fn named(&self, name: &str) -> Result<Option<(&'a Element, &'a Element)>, SceneError> {
        let mut found = None;
        for (i, c) in self.el.children.iter().enumerate() {
            if c.attr("name") == Some(name) {
                if found.is_some() {
                    return Err(self.fail(&c.loc, name, "given twice"));
                }
                self.used.borrow_mut()[i] = true;
                found = Some((c, self.resolve(c)?));
            }
        }
        Ok(found)
    }

    /// The value attribute of a parameter element of one of `tags`.
    fn scalar(&self, name: &str, tags: &[&str]) -> Result<Option<(&'a Element, &'a str)>, SceneError> {
        let Some((written, el)) = self.named(name)? else { return Ok(None) };
        if !tags.contains(&el.tag.as_str()) {
            return Err(self.fail(
                &written.loc,
                name,
                format!("must be a <{}>, got <{}>", tags.join("> or <"), el.tag),
            ));
        }
        let v = el.attr("value").ok_or_else(|| self.fail(&el.loc, name, "needs a value attribute"))?;
        Ok(Some((el, v)))
    }

    /// The tag of the child named `name`, without reading it.
    pub fn tag_of(&self, name: &str) -> Option<&'a str> {
        let c = self.el.children.iter().find(|c| c.attr("name") == Some(name))?;
        Some(self.resolve(c).ok()?.tag.as_str())
    }

    pub fn float(&self, name: &str) -> Result<Option<f64>, SceneError> {
        let Some((el, v)) = self.scalar(name, &["float", "integer"])? else { return Ok(None) };
        match v.trim().parse::<f64>() {
            Ok(x) if x.is_finite() => Ok(Some(x)),
            _ => Err(self.fail(&el.loc, name, format!("'{v}' is not a finite number"))),
        }
    }

    pub fn float_or(&self, name: &str, default: f64) -> Result<f64, SceneError> {
        Ok(self.float(name)?.unwrap_or(default))
    }

    /// A float within [lo, hi].
    pub fn float_in(&self, name: &str, default: f64, lo: f64, hi: f64) -> Result<f64, SceneError> {
        let v = self.float_or(name, default)?;
        if !(lo..=hi).contains(&v) {
            let loc = self.named_loc(name);
            return Err(self.fail(&loc, name, format!("must be in [{lo}, {hi}], got {v}")));
        }
        Ok(v)
    }

    /// Where parameter `name` is written (the plugin itself where it is not).
    pub fn named_loc(&self, name: &str) -> Loc {
        self.el.children.iter().find(|c| c.attr("name") == Some(name)).map_or(self.el.loc.clone(), |c| c.loc.clone())
    }

    pub fn integer(&self, name: &str) -> Result<Option<i64>, SceneError> {
        let Some((el, v)) = self.scalar(name, &["integer"])? else { return Ok(None) };
        v.trim().parse::<i64>().map(Some).map_err(|_| self.fail(&el.loc, name, format!("'{v}' is not an integer")))
    }

    pub fn boolean(&self, name: &str, default: bool) -> Result<bool, SceneError> {
        let Some((el, v)) = self.scalar(name, &["boolean"])? else { return Ok(default) };
        match v.trim() {
            "true" => Ok(true),
            "false" => Ok(false),
            _ => Err(self.fail(&el.loc, name, format!("'{v}' is not true or false"))),
        }
    }

    pub fn string(&self, name: &str) -> Result<Option<(String, Loc)>, SceneError> {
        Ok(self.scalar(name, &["string"])?.map(|(el, v)| (v.to_string(), el.loc.clone())))
    }

    pub fn point(&self, name: &str) -> Result<Option<DVec3>, SceneError> {
        let Some((written, el)) = self.named(name)? else { return Ok(None) };
        if !matches!(el.tag.as_str(), "point" | "vector") {
            return Err(self.fail(&written.loc, name, format!("must be a <point> or <vector>, got <{}>", el.tag)));
        }
        xyz(el, 0.0).map(Some).map_err(|m| self.fail(&el.loc, name, m))
    }

    pub fn transform(&self, name: &str) -> Result<Option<DAffine3>, SceneError> {
        let Some((written, el)) = self.named(name)? else { return Ok(None) };
        if el.tag != "transform" {
            return Err(self.fail(&written.loc, name, format!("must be a <transform>, got <{}>", el.tag)));
        }
        transform(el).map(Some)
    }

    /// A colour: `<rgb>`, `<spectrum>` or `<float>` (grey), read for `usage`.
    pub fn color(&self, name: &str, usage: Use) -> Result<Option<Color>, SceneError> {
        match self.value(name, usage)? {
            None => Ok(None),
            Some(Value::Color(c)) => Ok(Some(c)),
            Some(Value::Texture(t)) => Err(self.fail(
                t.loc(),
                name,
                format!("a texture ('{}') is not supported here yet; give a colour", t.kind),
            )),
        }
    }

    /// A colour or a texture object.
    pub fn value(&self, name: &str, usage: Use) -> Result<Option<Value<'a>>, SceneError> {
        let Some((written, el)) = self.named(name)? else { return Ok(None) };
        let fail = |m: String| self.fail(&el.loc, name, m);
        let c = match el.tag.as_str() {
            "rgb" | "color" => {
                let v = el.attr("value").ok_or_else(|| fail("needs a value attribute".into()))?;
                let n = numbers(v).map_err(fail)?;
                match n[..] {
                    [g] => Color::splat(g as f32),
                    [r, g, b] => Color::new(r as f32, g as f32, b as f32),
                    _ => return Err(fail(format!("an <rgb> has 1 or 3 values, got {}", n.len()))),
                }
            }
            "float" | "integer" => {
                let v = el.attr("value").ok_or_else(|| fail("needs a value attribute".into()))?;
                let x = v.trim().parse::<f64>().map_err(|_| fail(format!("'{v}' is not a number")))?;
                Color::splat(x as f32)
            }
            "spectrum" => spectrum_value(el, usage).map_err(fail)?,
            "texture" => return Ok(Some(Value::Texture(Plugin::new(el, self.ids)?))),
            t => return Err(self.fail(&written.loc, name, format!("must be a colour or a texture, got <{t}>"))),
        };
        if !c.is_finite() {
            return Err(fail("must be finite".into()));
        }
        Ok(Some(Value::Color(c)))
    }

    /// The nested objects of tag `tag` (named or not, through references),
    /// marked read.
    pub fn objects(&self, tag: &str) -> Result<Vec<Plugin<'a>>, SceneError> {
        let mut out = Vec::new();
        for (i, c) in self.el.children.iter().enumerate() {
            let el = self.resolve(c)?;
            if el.tag == tag {
                self.used.borrow_mut()[i] = true;
                out.push(Plugin::new(el, self.ids)?);
            }
        }
        Ok(out)
    }

    /// The nested objects of tag `tag` with the name each is given (a
    /// `<ref name="interior" id="...">` or `<medium name="interior">`),
    /// marked read.
    pub fn named_objects(&self, tag: &str) -> Result<Vec<(Option<&'a str>, Plugin<'a>)>, SceneError> {
        let mut out = Vec::new();
        for (i, c) in self.el.children.iter().enumerate() {
            let el = self.resolve(c)?;
            if el.tag == tag {
                self.used.borrow_mut()[i] = true;
                out.push((c.attr("name"), Plugin::new(el, self.ids)?));
            }
        }
        Ok(out)
    }

    /// The object child named `name` if it is a `<tag>` (through a
    /// reference), marked read; `None` where there is no child of that
    /// name or it is something else (left for the other readers).
    pub fn object_named(&self, name: &str, tag: &str) -> Result<Option<Plugin<'a>>, SceneError> {
        if self.tag_of(name) != Some(tag) {
            return Ok(None);
        }
        let Some((_, el)) = self.named(name)? else { return Ok(None) };
        Plugin::new(el, self.ids).map(Some)
    }

    /// At most one nested object of tag `tag`.
    pub fn object(&self, tag: &str) -> Result<Option<Plugin<'a>>, SceneError> {
        let mut all = self.objects(tag)?;
        if all.len() > 1 {
            return Err(self.fail(all[1].loc(), tag, format!("at most one <{tag}> is allowed here")));
        }
        Ok(all.pop())
    }

    /// Every child not read is an error: a parameter or object this
    /// plugin does not support (Mitsuba refuses unqueried properties too).
    pub fn finish(&self, supported: &str) -> Result<(), SceneError> {
        for (c, used) in self.el.children.iter().zip(self.used.borrow().iter()) {
            if !used {
                let what = c.attr("name").map_or_else(|| format!("<{}>", c.tag), |n| format!("'{n}'"));
                return Err(error(
                    &c.loc,
                    format!("{} '{}'", self.el.tag, self.kind),
                    format!(
                        "{what} is not supported by photonmap's '{}' {} (supported: {supported})",
                        self.kind, self.el.tag
                    ),
                ));
            }
        }
        Ok(())
    }
}

fn spectrum_value(el: &Element, usage: Use) -> Result<Color, String> {
    if el.attr("filename").is_some() {
        return Err("a spectrum read from a file is not supported; give wavelength:value pairs".into());
    }
    let v = el.attr("value").ok_or("needs a value attribute")?;
    if !v.contains(':') {
        let x: f64 = v.trim().parse().map_err(|_| format!("'{v}' is not a number"))?;
        return Ok(spectrum::uniform(x, usage));
    }
    let mut w = Vec::new();
    let mut vals = Vec::new();
    for pair in v.split(',').map(str::trim).filter(|p| !p.is_empty()) {
        let (a, b) = pair.split_once(':').ok_or_else(|| format!("'{pair}' is not wavelength:value"))?;
        let (a, b): (f64, f64) = match (a.trim().parse(), b.trim().parse()) {
            (Ok(a), Ok(b)) => (a, b),
            _ => return Err(format!("'{pair}' is not wavelength:value")),
        };
        if let Some(&last) = w.last() {
            if !(a > last) {
                return Err("wavelengths must increase".into());
            }
        }
        w.push(a);
        vals.push(b);
    }
    if w.is_empty() {
        return Err("no wavelength:value pairs".into());
    }
    Ok(spectrum::pairs_to_rgb(&w, &vals, usage).0)
}

/// Numbers separated by commas and/or white space.
pub fn numbers(s: &str) -> Result<Vec<f64>, String> {
    s.split(|c: char| c == ',' || c.is_whitespace())
        .filter(|t| !t.is_empty())
        .map(|t| t.parse::<f64>().ok().filter(|x| x.is_finite()).ok_or_else(|| format!("'{t}' is not a finite number")))
        .collect()
}

/// x, y, z attributes (missing ones `default`), or a `value` of one number
/// (all three) or three.
fn xyz(el: &Element, default: f64) -> Result<DVec3, String> {
    if let Some(v) = el.attr("value") {
        let n = numbers(v)?;
        return match n[..] {
            [a] => Ok(DVec3::splat(a)),
            [a, b, c] => Ok(DVec3::new(a, b, c)),
            _ => Err(format!("'{v}' must be 1 or 3 numbers")),
        };
    }
    let get = |k: &str| -> Result<f64, String> {
        match el.attr(k) {
            None => Ok(default),
            Some(t) => {
                t.trim().parse::<f64>().ok().filter(|x| x.is_finite()).ok_or(format!("{k}='{t}' is not a number"))
            }
        }
    };
    Ok(DVec3::new(get("x")?, get("y")?, get("z")?))
}

/// A `<transform>`'s steps, each applied after the ones before it (the
/// first written acts first), as Mitsuba composes them.
pub fn transform(el: &Element) -> Result<DAffine3, SceneError> {
    let mut m = DAffine3::IDENTITY;
    for step in &el.children {
        let fail = |msg: String| error(&step.loc, format!("transform.{}", step.tag), msg);
        let allowed: &[&str] = match step.tag.as_str() {
            "translate" | "scale" => &["x", "y", "z", "value"],
            "rotate" => &["x", "y", "z", "value", "angle"],
            "lookat" => &["origin", "target", "up"],
            "matrix" => &["value"],
            t => return Err(fail(format!("<{t}> is not a transform step (translate, rotate, scale, matrix, lookat)"))),
        };
        if let Some((k, _)) = step.attrs.iter().find(|(k, _)| !allowed.contains(&k.as_str())) {
            return Err(fail(format!("unknown attribute '{k}'")));
        }
        let next = match step.tag.as_str() {
            "translate" => DAffine3::from_translation(xyz(step, 0.0).map_err(fail)?),
            "scale" => DAffine3::from_scale(xyz(step, 1.0).map_err(fail)?),
            "rotate" => {
                let axis = xyz(step, 0.0).map_err(fail)?;
                let angle = step.attr("angle").ok_or_else(|| fail("needs an angle (degrees)".into()))?;
                let angle: f64 = angle.trim().parse().map_err(|_| fail(format!("angle '{angle}' is not a number")))?;
                let axis = axis.try_normalize().ok_or_else(|| fail("the rotation axis cannot be zero".into()))?;
                DAffine3::from_axis_angle(axis, angle.to_radians())
            }
            "lookat" => {
                let vec = |k: &str| -> Result<Option<DVec3>, SceneError> {
                    step.attr(k)
                        .map(|v| match numbers(v).map_err(&fail)?[..] {
                            [a, b, c] => Ok(DVec3::new(a, b, c)),
                            _ => Err(fail(format!("{k} must be 3 numbers"))),
                        })
                        .transpose()
                };
                let origin = vec("origin")?.ok_or_else(|| fail("needs an origin".into()))?;
                let target = vec("target")?.ok_or_else(|| fail("needs a target".into()))?;
                let dir = (target - origin).try_normalize().ok_or_else(|| fail("target equals origin".into()))?;
                let up = match vec("up")? {
                    Some(u) if u != DVec3::ZERO => u,
                    _ => dir.any_orthonormal_vector(),
                };
                // Mitsuba's look_at: the frame (left, up, dir) at origin.
                let left = up.cross(dir).try_normalize().ok_or_else(|| fail("up is parallel to the view".into()))?;
                let new_up = dir.cross(left);
                DAffine3::from_mat3_translation(DMat3::from_cols(left, new_up, dir), origin)
            }
            _ => {
                let v = step.attr("value").ok_or_else(|| fail("needs a value".into()))?;
                let n = numbers(v).map_err(fail)?;
                // Row-major, as written.
                let r = |i: usize, j: usize, k: usize| n[i * k + j];
                match n.len() {
                    9 => DAffine3::from_mat3(DMat3::from_cols_array(&[
                        r(0, 0, 3),
                        r(1, 0, 3),
                        r(2, 0, 3),
                        r(0, 1, 3),
                        r(1, 1, 3),
                        r(2, 1, 3),
                        r(0, 2, 3),
                        r(1, 2, 3),
                        r(2, 2, 3),
                    ])),
                    16 => {
                        if (r(3, 0, 4), r(3, 1, 4), r(3, 2, 4), r(3, 3, 4)) != (0.0, 0.0, 0.0, 1.0) {
                            return Err(fail("a projective matrix (last row not 0 0 0 1) is not supported".into()));
                        }
                        DAffine3::from_mat3_translation(
                            DMat3::from_cols(
                                DVec3::new(r(0, 0, 4), r(1, 0, 4), r(2, 0, 4)),
                                DVec3::new(r(0, 1, 4), r(1, 1, 4), r(2, 1, 4)),
                                DVec3::new(r(0, 2, 4), r(1, 2, 4), r(2, 2, 4)),
                            ),
                            DVec3::new(r(0, 3, 4), r(1, 3, 4), r(2, 3, 4)),
                        )
                    }
                    k => return Err(fail(format!("a matrix has 9 or 16 values, got {k}"))),
                }
            }
        };
        m = next * m;
    }
    if !m.is_finite() {
        return Err(error(&el.loc, "transform", "the transform is not finite"));
    }
    Ok(m)
}
