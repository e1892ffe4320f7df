//! Tests of the xacro expansion: literals, properties, macros, blocks, conditions, includes,
//! error messages and the mapping of output lines back to their sources.

use std::collections::BTreeMap;
use std::path::PathBuf;

use rover_pyexpr::Value;

use super::expand_file;
use super::properties::literal_value;
use crate::description::resource::ResourcePaths;
use crate::error::{Result, SimError};

#[test]
fn literals_read_like_xacro() {
    assert_eq!(literal_value("3"), Value::Int(3));
    assert_eq!(literal_value("0.5"), Value::Float(0.5));
    assert_eq!(literal_value("true"), Value::Bool(true));
    assert_eq!(literal_value("1_000"), Value::Str("1_000".into()));
    assert_eq!(literal_value("'0.5'"), Value::Str("0.5".into()));
    assert_eq!(literal_value("base_link"), Value::Str("base_link".into()));
    assert_eq!(literal_value("infinity"), Value::Float(f64::INFINITY));
    assert_eq!(literal_value("1 2"), Value::Str("1 2".into()));
}

fn expand(files: &[(&str, &str)], args: &[(&str, &str)]) -> Result<String> {
    let dir = tempfile::tempdir().map_err(|source| SimError::Io {
        path: PathBuf::from("tempdir"),
        source,
    })?;
    for (name, text) in files {
        let p = dir.path().join(name);
        if let Some(parent) = p.parent() {
            let _ = std::fs::create_dir_all(parent);
        }
        std::fs::write(&p, text).map_err(|source| SimError::Io {
            path: p.clone(),
            source,
        })?;
    }
    let args = args
        .iter()
        .map(|(k, v)| ((*k).to_owned(), (*v).to_owned()))
        .collect();
    let out = expand_file(
        &dir.path().join(files[0].0),
        &args,
        &ResourcePaths::default(),
    )?;
    Ok(out.text)
}

const HEAD: &str = r#"<robot name="r" xmlns:xacro="http://www.ros.org/wiki/xacro">"#;

#[test]
fn properties_macros_blocks_and_conditions() -> Result<()> {
    let text = format!(
        r#"{HEAD}
  <xacro:property name="r" value="0.033"/>
  <xacro:property name="d" value="${{2*r}}"/>
  <xacro:arg name="use_cam" default="true"/>
  <xacro:macro name="wheel" params="side reflect:=1 *origin **extra">
    <link name="${{side}}_wheel"><inertial><mass value="${{d*reflect}}"/></inertial></link>
    <joint name="${{side}}_joint" type="continuous"><xacro:insert_block name="origin"/></joint>
    <gazebo reference="${{side}}_wheel"><xacro:insert_block name="extra"/></gazebo>
  </xacro:macro>
  <xacro:wheel side="left">
    <origin xyz="0 ${{d}} 0"/>
    <gz><mu1>0.5</mu1></gz>
  </xacro:wheel>
  <xacro:wheel side="right" reflect="-1">
    <origin xyz="0 -${{d}} 0"/>
    <gz/>
  </xacro:wheel>
  <xacro:if value="$(arg use_cam)"><link name="camera"/></xacro:if>
  <xacro:unless value="${{r > 1}}"><link name="small"/></xacro:unless>
  <gazebo><wheelDiameter>${{d}}</wheelDiameter></gazebo>
</robot>"#
    );
    let out = expand(&[("r.urdf.xacro", &text)], &[])?;
    assert!(out.contains(r#"<link name="left_wheel">"#), "{out}");
    assert!(out.contains(r#"<mass value="0.066"/>"#), "{out}");
    assert!(out.contains(r#"<mass value="-0.066"/>"#), "{out}");
    assert!(out.contains(r#"<origin xyz="0 -0.066 0"/>"#), "{out}");
    assert!(out.contains("<mu1>0.5</mu1>"), "{out}");
    assert!(out.contains(r#"<link name="camera"/>"#), "{out}");
    assert!(out.contains(r#"<link name="small"/>"#), "{out}");
    assert!(
        out.contains("<wheelDiameter>0.066</wheelDiameter>"),
        "{out}"
    );
    assert!(!out.contains("xacro"), "{out}");
    let off = expand(&[("r.urdf.xacro", &text)], &[("use_cam", "false")])?;
    assert!(!off.contains("camera"), "{off}");
    Ok(())
}

#[test]
fn includes_with_namespace_and_relative_paths() -> Result<()> {
    let main = format!(
        r#"{HEAD}
  <xacro:include filename="parts/common.xacro"/>
  <xacro:include filename="parts/common.xacro" ns="c"/>
  <link name="${{base}}"/><link name="${{c.base}}_2"/>
  <xacro:box_link name="b"/><xacro:c.box_link name="b2"/>
</robot>"#
    );
    let common = format!(
        r#"{HEAD}<xacro:property name="base" value="base_link"/>
<xacro:macro name="box_link" params="name"><link name="${{name}}"/></xacro:macro></robot>"#
    );
    let out = expand(
        &[("main.xacro", &main), ("parts/common.xacro", &common)],
        &[],
    )?;
    for name in ["base_link", "base_link_2", "b", "b2"] {
        assert!(out.contains(&format!(r#"<link name="{name}"/>"#)), "{out}");
    }
    Ok(())
}

fn message(result: Result<String>) -> String {
    match result {
        Ok(text) => format!("unexpectedly expanded: {text}"),
        Err(e) => e.to_string(),
    }
}

#[test]
fn errors_name_file_line_and_what_is_undefined() {
    let undefined = format!("{HEAD}\n<link name=\"${{nope}}\"/></robot>");
    let m = message(expand(&[("a.xacro", &undefined)], &[]));
    assert!(
        m.contains("a.xacro:2") && m.contains("undefined property \"nope\""),
        "{m}"
    );

    let no_macro = format!("{HEAD}\n\n<xacro:wheel side=\"l\"/></robot>");
    let m = message(expand(&[("a.xacro", &no_macro)], &[]));
    assert!(
        m.contains("a.xacro:3") && m.contains("unknown macro \"xacro:wheel\""),
        "{m}"
    );

    let no_arg = format!("{HEAD}\n<link name=\"$(arg robot)\"/></robot>");
    let m = message(expand(&[("a.xacro", &no_arg)], &[]));
    assert!(
        m.contains("undefined arg \"robot\"") && m.contains("--xacro-arg"),
        "{m}"
    );

    let cycle_a = format!("{HEAD}<xacro:include filename=\"b.xacro\"/></robot>");
    let cycle_b = format!("{HEAD}\n<xacro:include filename=\"a.xacro\"/></robot>");
    let m = message(expand(&[("a.xacro", &cycle_a), ("b.xacro", &cycle_b)], &[]));
    assert!(
        m.contains("include cycle") && m.contains("b.xacro:2"),
        "{m}"
    );

    let recursive = format!(
        "{HEAD}<xacro:macro name=\"m\" params=\"\"><xacro:m/></xacro:macro><xacro:m/></robot>"
    );
    let m = message(expand(&[("a.xacro", &recursive)], &[]));
    assert!(m.contains("nested deeper"), "{m}");

    let selfref = format!(
        "{HEAD}<xacro:property name=\"a\" value=\"${{a+1}}\"/><link name=\"${{a}}\"/></robot>"
    );
    let m = message(expand(&[("a.xacro", &selfref)], &[]));
    assert!(m.contains("in terms of itself"), "{m}");

    let missing =
        format!("{HEAD}<xacro:macro name=\"m\" params=\"x\"/>\n<xacro:m y=\"1\"/></robot>");
    let m = message(expand(&[("a.xacro", &missing)], &[]));
    assert!(
        m.contains("unknown parameter \"y\"") && m.contains("a.xacro:2"),
        "{m}"
    );
}

#[test]
fn output_lines_map_back_to_sources() -> Result<()> {
    let dir = tempfile::tempdir().map_err(|source| SimError::Io {
        path: PathBuf::from("tempdir"),
        source,
    })?;
    let p = dir.path().join("m.xacro");
    let text = format!(
        "{HEAD}\n<xacro:macro name=\"l\" params=\"n\">\n<link name=\"${{n}}\"/>\n</xacro:macro>\n<xacro:l n=\"a\"/>\n</robot>"
    );
    std::fs::write(&p, text).map_err(|source| SimError::Io {
        path: p.clone(),
        source,
    })?;
    let out = expand_file(&p, &BTreeMap::new(), &ResourcePaths::default())?;
    let line = out
        .text
        .lines()
        .position(|l| l.contains("<link name=\"a\"/>"))
        .ok_or_else(|| SimError::Setup("link missing".into()))?;
    let loc = out
        .source_of(line as u32 + 1)
        .ok_or_else(|| SimError::Setup("no source".into()))?;
    assert_eq!(loc.line, Some(3));
    Ok(())
}
