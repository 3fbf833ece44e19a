//! Finding, reading and checking a URDF file, with errors that name the
//! element at fault and its line.
//!
//! The file is read by `urdf-rs`. Its errors carry no position (it writes
//! the document anew before deserializing it), so the XML is first walked
//! here with the parser `urdf-rs` builds on (RustyXML): a syntax error gets
//! its line and column, and an element `urdf-rs` rejects is found by reading
//! each top-level element alone, so every bad element is reported, each by
//! its tag, name and line.
//!
//! Only what the dynamics reads is given to `urdf-rs`: the links with their
//! first `<inertial>` (as urdfdom, Pinocchio's reader, takes it) and the
//! joints. Visuals, collisions, materials, `<transmission>`, `<gazebo>` and
//! any other element are left out unread, so a geometry urdfdom accepts and
//! `urdf-rs` does not (a `<texture/>` without a file name) stops nothing.

use std::path::Path;

/// The URDF joint types, as the file spells them.
pub(super) const JOINT_TYPES: &[&str] = &[
    "revolute",
    "continuous",
    "prismatic",
    "fixed",
    "floating",
    "planar",
];

/// Where each top-level element of the file starts.
#[derive(Debug, Default)]
pub(super) struct Lines(Vec<(String, String, u32)>);

impl Lines {
    /// `joint `elbow` (line 42)`: an element by its tag and name attribute.
    pub(super) fn describe(&self, tag: &str, name: &str) -> String {
        match self.0.iter().find(|(t, n, _)| t == tag && n == name) {
            Some((_, _, line)) => format!("{tag} `{name}` (line {line})"),
            None => format!("{tag} `{name}`"),
        }
    }
}

/// The file read: the robot and where its elements are.
pub(super) struct Read {
    /// The robot, as `urdf-rs` reads it.
    pub robot: urdf_rs::Robot,
    /// The lines of its links and joints.
    pub lines: Lines,
}

/// The robot in the file at `path`, or the messages of everything wrong
/// with the file.
pub(super) fn read(path: &Path) -> Result<Read, Vec<String>> {
    let text = std::fs::read_to_string(path).map_err(|e| {
        vec![format!(
            "cannot read the URDF file `{}`: {e}",
            path.display()
        )]
    })?;
    let lines = walk(&text).map_err(|e| vec![format!("the URDF is not well-formed XML: {e}")])?;
    let whole: xml::Element = text
        .parse()
        .map_err(|e| vec![format!("the URDF is not well-formed XML: {e}")])?;
    if whole.name != "robot" {
        return Err(vec![format!(
            "the URDF's root element is `<{}>`; a URDF is a `<robot>`",
            whole.name
        )]);
    }
    let root = dynamics_only(&whole);
    if root.get_children("link", None).next().is_none() {
        return Err(vec![
            "the URDF has no `<link>`: a robot is at least one link".into(),
        ]);
    }
    // Joints of unknown type and elements `urdf-rs` rejects are reported
    // together, so one build shows every mistake of the file.
    let mut errors = joint_types(&root, &lines);
    match urdf_rs::read_from_string(&root.to_string()) {
        Ok(robot) if errors.is_empty() => return Ok(Read { robot, lines }),
        Ok(_) => {}
        Err(whole) => {
            let known = errors.is_empty();
            errors.extend(element_errors(&root, &lines, &whole.to_string(), known));
        }
    }
    Err(errors)
}

/// The robot with its links (name and first `<inertial>`) and joints
/// only.
fn dynamics_only(robot: &xml::Element) -> xml::Element {
    let mut out = robot.clone();
    out.children = robot
        .children
        .iter()
        .filter_map(|node| {
            let xml::Xml::ElementNode(e) = node else {
                return None;
            };
            match e.name.as_str() {
                "joint" => Some(node.clone()),
                "link" => {
                    let mut link = e.clone();
                    link.children = e
                        .get_children("inertial", None)
                        .take(1)
                        .map(|i| xml::Xml::ElementNode(i.clone()))
                        .collect();
                    Some(xml::Xml::ElementNode(link))
                }
                _ => None,
            }
        })
        .collect();
    out
}

/// Walks the XML: checks that it is well-formed and records the line of
/// each element directly under the root.
fn walk(text: &str) -> Result<Lines, String> {
    let mut parser = xml::Parser::new();
    let mut open: Vec<String> = Vec::new();
    let mut lines = Lines::default();
    let mut seen_root = false;
    // Fed a line at a time, so each event is known to come from the line
    // just fed.
    for (k, line) in text.split_inclusive('\n').enumerate() {
        let number = k as u32 + 1;
        parser.feed_str(line);
        for event in &mut parser {
            match event.map_err(|e| format!("line {}, column {}: {}", e.line, e.col, e.msg))? {
                xml::Event::ElementStart(tag) => {
                    if open.is_empty() && seen_root {
                        return Err(format!(
                            "line {number}: `<{}>` after the root element has closed",
                            tag.name
                        ));
                    }
                    if open.len() == 1 {
                        let name = tag
                            .attributes
                            .get(&("name".to_string(), None))
                            .cloned()
                            .unwrap_or_default();
                        lines.0.push((tag.name.clone(), name, number));
                    }
                    seen_root = true;
                    open.push(tag.name);
                }
                xml::Event::ElementEnd(tag) => match open.pop() {
                    Some(o) if o == tag.name => {}
                    Some(o) => {
                        return Err(format!("line {number}: `</{}>` closes `<{o}>`", tag.name))
                    }
                    None => return Err(format!("line {number}: `</{}>` closes nothing", tag.name)),
                },
                _ => {}
            }
        }
    }
    match open.last() {
        Some(o) => Err(format!("`<{o}>` is never closed")),
        None if !seen_root => Err("the file holds no element".into()),
        None => Ok(lines),
    }
}

/// An error for each joint whose type is missing or not a URDF type.
fn joint_types(root: &xml::Element, lines: &Lines) -> Vec<String> {
    let mut errors = Vec::new();
    for joint in root.get_children("joint", None) {
        let name = joint.get_attribute("name", None).unwrap_or_default();
        let at = lines.describe("joint", name);
        match joint.get_attribute("type", None) {
            Some(t) if JOINT_TYPES.contains(&t) => {}
            Some(t) => {
                let hint = crate::ctxt::did_you_mean(t, JOINT_TYPES.iter().copied())
                    .map(|s| format!("; did you mean `{s}`?"))
                    .unwrap_or_default();
                errors.push(format!(
                    "URDF {at}: unknown joint type `{t}`; the types are {}{hint}",
                    JOINT_TYPES.join(", ")
                ));
            }
            None => errors.push(format!(
                "URDF {at}: no `type`; the types are {}",
                JOINT_TYPES.join(", ")
            )),
        }
    }
    errors
}

/// When `urdf-rs` rejects the file: each top-level element read alone, and
/// an error for each one it rejects (joints of unknown type left to
/// [`joint_types`]); the whole file's error when none is rejected alone
/// and `nothing_else` was found.
fn element_errors(
    root: &xml::Element,
    lines: &Lines,
    whole: &str,
    nothing_else: bool,
) -> Vec<String> {
    let mut errors = Vec::new();
    for node in &root.children {
        let xml::Xml::ElementNode(e) = node else {
            continue;
        };
        if !matches!(e.name.as_str(), "link" | "joint") {
            continue;
        }
        let typed = e.get_attribute("type", None);
        if e.name == "joint" && !typed.is_some_and(|t| JOINT_TYPES.contains(&t)) {
            continue;
        }
        let alone = format!("<robot name=\"alone\">{e}</robot>");
        if let Err(err) = urdf_rs::read_from_string(&alone) {
            let name = e.get_attribute("name", None).unwrap_or_default();
            errors.push(format!(
                "URDF {}: {}",
                lines.describe(&e.name, name),
                plain(&err.to_string())
            ));
        }
    }
    if errors.is_empty() && nothing_else {
        errors.push(format!("the URDF cannot be read: {}", plain(whole)));
    }
    errors
}

/// An error of `urdf-rs` without the prefix its deserializer adds.
fn plain(message: &str) -> &str {
    message.strip_prefix("custom: ").unwrap_or(message)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_syntax_error_has_its_line() {
        let e = walk("<robot>\n<link name=\"a\">\n</joint>\n</robot>").unwrap_err();
        assert_eq!(e, "line 3: `</joint>` closes `<link>`");
        let e = walk("<robot>\n<link name=a/>\n</robot>").unwrap_err();
        assert!(e.starts_with("line 2, column"), "{e}");
        let e = walk("<robot>\n<link name=\"a\">\n").unwrap_err();
        assert_eq!(e, "`<link>` is never closed");
    }

    fn read_text(text: &str) -> Result<Read, Vec<String>> {
        let dir =
            std::env::temp_dir().join(format!("appell-read-{}-{}", std::process::id(), text.len()));
        std::fs::create_dir_all(&dir).unwrap();
        let path = dir.join("r.urdf");
        std::fs::write(&path, text).unwrap();
        let out = read(&path);
        std::fs::remove_dir_all(&dir).unwrap();
        out
    }

    #[test]
    fn only_the_dynamics_is_read() {
        // A texture without a file (iCub, Romeo), a transmission, a gazebo
        // tag, a visual whose geometry urdf-rs would reject: none matters.
        let read = read_text(
            r#"<robot name="r">
              <material name="grey"><texture/><color rgba="1 1 1 1"/></material>
              <link name="a">
                <visual><geometry><mesh/></geometry><material name="m"><texture/></material></visual>
                <inertial><mass value="2"/><inertia ixx="1" iyy="1" izz="1" ixy="0" iyz="0" ixz="0"/></inertial>
                <inertial><mass value="3"/><inertia ixx="1" iyy="1" izz="1" ixy="0" iyz="0" ixz="0"/></inertial>
              </link>
              <link name="b"/>
              <joint name="j" type="continuous"><parent link="a"/><child link="b"/></joint>
              <transmission name="t"><joint name="j"/></transmission>
              <gazebo reference="a"><mu1>0.2</mu1></gazebo>
            </robot>"#,
        )
        .map_err(|e| e.join("; "))
        .unwrap();
        assert_eq!(read.robot.links.len(), 2);
        // The first inertial, as urdfdom reads it.
        assert_eq!(read.robot.links[0].inertial.mass.value, 2.0);
        assert_eq!(read.robot.joints.len(), 1);
    }

    #[test]
    fn a_robot_without_links_is_named_so() {
        let e = read_text("<robot>\n</robot>").map(|_| ()).unwrap_err();
        assert_eq!(
            e,
            ["the URDF has no `<link>`: a robot is at least one link"]
        );
    }

    #[test]
    fn elements_are_found_by_line() {
        let lines =
            walk("<robot>\n  <link name=\"a\"/>\n  <joint name=\"j\">\n</joint></robot>").unwrap();
        assert_eq!(lines.describe("joint", "j"), "joint `j` (line 3)");
        assert_eq!(lines.describe("link", "a"), "link `a` (line 2)");
        assert_eq!(lines.describe("link", "b"), "link `b`");
    }
}
