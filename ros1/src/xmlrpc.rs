//! XML-RPC over HTTP/1.x, as far as the ROS 1 master and slave APIs use it: calls with string,
//! int, boolean, double and array parameters, responses of the `[code, status, value]` shape.
//!
//! Written here rather than taken from a crate: the ROS subset is a few hundred lines on
//! `std::net` and roxmltree (already in the build), where the XML-RPC crates bring an HTTP
//! stack and an async runtime.

use std::io::{BufRead, BufReader, Read, Write};
use std::net::{TcpStream, ToSocketAddrs};
use std::time::Duration;

use crate::error::{Error, Result};

/// An XML-RPC value.
#[derive(Debug, Clone, PartialEq)]
pub enum Value {
    /// `<int>` / `<i4>`.
    Int(i32),
    /// `<boolean>`.
    Bool(bool),
    /// `<string>` (or untyped text).
    Str(String),
    /// `<double>`.
    Double(f64),
    /// `<array>`.
    Array(Vec<Value>),
    /// `<struct>`, members in order.
    Struct(Vec<(String, Value)>),
}

impl Value {
    /// The string, if this is one.
    pub fn as_str(&self) -> Option<&str> {
        match self {
            Value::Str(s) => Some(s),
            _ => None,
        }
    }

    /// The integer, if this is one.
    pub fn as_int(&self) -> Option<i32> {
        match self {
            Value::Int(i) => Some(*i),
            _ => None,
        }
    }

    /// The items, if this is an array.
    pub fn as_array(&self) -> Option<&[Value]> {
        match self {
            Value::Array(a) => Some(a),
            _ => None,
        }
    }

    fn write_xml(&self, out: &mut String) {
        out.push_str("<value>");
        match self {
            Value::Int(i) => {
                out.push_str("<i4>");
                out.push_str(&i.to_string());
                out.push_str("</i4>");
            }
            Value::Bool(b) => {
                out.push_str(if *b {
                    "<boolean>1</boolean>"
                } else {
                    "<boolean>0</boolean>"
                });
            }
            Value::Str(s) => {
                out.push_str("<string>");
                escape_into(s, out);
                out.push_str("</string>");
            }
            Value::Double(d) => {
                out.push_str("<double>");
                out.push_str(&format!("{d:?}"));
                out.push_str("</double>");
            }
            Value::Array(items) => {
                out.push_str("<array><data>");
                for v in items {
                    v.write_xml(out);
                }
                out.push_str("</data></array>");
            }
            Value::Struct(members) => {
                out.push_str("<struct>");
                for (name, v) in members {
                    out.push_str("<member><name>");
                    escape_into(name, out);
                    out.push_str("</name>");
                    v.write_xml(out);
                    out.push_str("</member>");
                }
                out.push_str("</struct>");
            }
        }
        out.push_str("</value>");
    }
}

impl From<&str> for Value {
    fn from(s: &str) -> Self {
        Value::Str(s.to_owned())
    }
}

impl From<String> for Value {
    fn from(s: String) -> Self {
        Value::Str(s)
    }
}

impl From<i32> for Value {
    fn from(i: i32) -> Self {
        Value::Int(i)
    }
}

impl From<bool> for Value {
    fn from(b: bool) -> Self {
        Value::Bool(b)
    }
}

fn escape_into(s: &str, out: &mut String) {
    for c in s.chars() {
        match c {
            '<' => out.push_str("&lt;"),
            '>' => out.push_str("&gt;"),
            '&' => out.push_str("&amp;"),
            _ => out.push(c),
        }
    }
}

/// The body of a `methodCall`.
pub fn call_body(method: &str, params: &[Value]) -> String {
    let mut out = String::with_capacity(256);
    out.push_str("<?xml version=\"1.0\"?><methodCall><methodName>");
    escape_into(method, &mut out);
    out.push_str("</methodName><params>");
    for p in params {
        out.push_str("<param>");
        p.write_xml(&mut out);
        out.push_str("</param>");
    }
    out.push_str("</params></methodCall>");
    out
}

/// The body of a successful `methodResponse`.
pub fn response_body(value: &Value) -> String {
    let mut out = String::with_capacity(256);
    out.push_str("<?xml version=\"1.0\"?><methodResponse><params><param>");
    value.write_xml(&mut out);
    out.push_str("</param></params></methodResponse>");
    out
}

/// The body of a `methodResponse` carrying a fault.
pub fn fault_body(code: i32, text: &str) -> String {
    let mut out = String::from("<?xml version=\"1.0\"?><methodResponse><fault>");
    Value::Struct(vec![
        ("faultCode".to_owned(), Value::Int(code)),
        ("faultString".to_owned(), Value::from(text)),
    ])
    .write_xml(&mut out);
    out.push_str("</fault></methodResponse>");
    out
}

fn element_children<'a, 'i>(
    node: roxmltree::Node<'a, 'i>,
) -> impl Iterator<Item = roxmltree::Node<'a, 'i>> {
    node.children().filter(|n| n.is_element())
}

fn parse_value(node: roxmltree::Node<'_, '_>) -> Result<Value> {
    let Some(typed) = element_children(node).next() else {
        // Untyped text is a string.
        return Ok(Value::Str(node.text().unwrap_or("").to_owned()));
    };
    let text = || typed.text().unwrap_or("").trim();
    Ok(match typed.tag_name().name() {
        "i4" | "int" => Value::Int(
            text()
                .parse()
                .map_err(|_| Error::protocol(format!("bad XML-RPC int {:?}", text())))?,
        ),
        "boolean" => Value::Bool(text() == "1"),
        "string" => Value::Str(typed.text().unwrap_or("").to_owned()),
        "double" => Value::Double(
            text()
                .parse()
                .map_err(|_| Error::protocol(format!("bad XML-RPC double {:?}", text())))?,
        ),
        "array" => {
            let mut items = Vec::new();
            if let Some(data) = element_children(typed).find(|n| n.has_tag_name("data")) {
                for v in element_children(data).filter(|n| n.has_tag_name("value")) {
                    items.push(parse_value(v)?);
                }
            }
            Value::Array(items)
        }
        "struct" => {
            let mut members = Vec::new();
            for m in element_children(typed).filter(|n| n.has_tag_name("member")) {
                let name = element_children(m)
                    .find(|n| n.has_tag_name("name"))
                    .and_then(|n| n.text())
                    .unwrap_or("")
                    .to_owned();
                let value = match element_children(m).find(|n| n.has_tag_name("value")) {
                    Some(v) => parse_value(v)?,
                    None => Value::Str(String::new()),
                };
                members.push((name, value));
            }
            Value::Struct(members)
        }
        "nil" => Value::Str(String::new()),
        other => {
            return Err(Error::protocol(format!(
                "unsupported XML-RPC type <{other}>"
            )));
        }
    })
}

fn params_of(root: roxmltree::Node<'_, '_>) -> Result<Vec<Value>> {
    let mut out = Vec::new();
    if let Some(params) = element_children(root).find(|n| n.has_tag_name("params")) {
        for p in element_children(params).filter(|n| n.has_tag_name("param")) {
            match element_children(p).find(|n| n.has_tag_name("value")) {
                Some(v) => out.push(parse_value(v)?),
                None => return Err(Error::protocol("XML-RPC <param> without <value>")),
            }
        }
    }
    Ok(out)
}

/// Parses a `methodCall`: the method name and its parameters.
pub fn parse_call(body: &str) -> Result<(String, Vec<Value>)> {
    let doc = roxmltree::Document::parse(body)
        .map_err(|e| Error::protocol(format!("XML-RPC call is not XML: {e}")))?;
    let root = doc.root_element();
    if !root.has_tag_name("methodCall") {
        return Err(Error::protocol("XML-RPC body is not a <methodCall>"));
    }
    let method = element_children(root)
        .find(|n| n.has_tag_name("methodName"))
        .and_then(|n| n.text())
        .ok_or_else(|| Error::protocol("XML-RPC call without <methodName>"))?
        .trim()
        .to_owned();
    Ok((method, params_of(root)?))
}

/// Parses a `methodResponse`: its value, or the fault as an error.
pub fn parse_response(body: &str) -> Result<Value> {
    let doc = roxmltree::Document::parse(body)
        .map_err(|e| Error::protocol(format!("XML-RPC response is not XML: {e}")))?;
    let root = doc.root_element();
    if let Some(fault) = element_children(root).find(|n| n.has_tag_name("fault")) {
        let text = element_children(fault)
            .next()
            .map(parse_value)
            .transpose()?
            .map(|v| format!("{v:?}"))
            .unwrap_or_default();
        return Err(Error::protocol(format!("XML-RPC fault: {text}")));
    }
    params_of(root)?
        .into_iter()
        .next()
        .ok_or_else(|| Error::protocol("XML-RPC response without a value"))
}

/// Host and port of an `http://host:port/` URI.
pub fn host_port(uri: &str) -> Result<(String, u16)> {
    let rest = uri
        .strip_prefix("http://")
        .ok_or_else(|| Error::protocol(format!("not an http:// URI: {uri}")))?;
    let authority = rest.split('/').next().unwrap_or(rest);
    let (host, port) = authority
        .rsplit_once(':')
        .ok_or_else(|| Error::protocol(format!("URI without a port: {uri}")))?;
    let port = port
        .parse()
        .map_err(|_| Error::protocol(format!("bad port in URI {uri}")))?;
    Ok((host.to_owned(), port))
}

/// Reads one HTTP message (request or response) from `reader`: its first line and body.
pub fn read_http<R: BufRead>(reader: &mut R) -> Result<(String, String)> {
    let mut first = String::new();
    if reader.read_line(&mut first)? == 0 {
        return Err(Error::protocol("connection closed before an HTTP message"));
    }
    let mut length: Option<usize> = None;
    loop {
        let mut line = String::new();
        if reader.read_line(&mut line)? == 0 {
            break;
        }
        let line = line.trim_end();
        if line.is_empty() {
            break;
        }
        if let Some((name, value)) = line.split_once(':')
            && name.trim().eq_ignore_ascii_case("content-length")
        {
            length = value.trim().parse().ok();
        }
    }
    let mut body = Vec::new();
    match length {
        Some(n) => {
            if n > 64 << 20 {
                return Err(Error::protocol(format!("HTTP body of {n} bytes")));
            }
            body.resize(n, 0);
            reader.read_exact(&mut body)?;
        }
        None => {
            reader.take(64 << 20).read_to_end(&mut body)?;
        }
    }
    let body = String::from_utf8(body)
        .map_err(|_| Error::protocol("XML-RPC body is not UTF-8".to_owned()))?;
    Ok((first.trim_end().to_owned(), body))
}

/// Calls `method` on the XML-RPC server at `uri`, waiting at most `timeout` for each of the
/// connection, the request and the reply.
pub fn call(uri: &str, method: &str, params: &[Value], timeout: Duration) -> Result<Value> {
    let (host, port) = host_port(uri)?;
    let addr = (host.as_str(), port)
        .to_socket_addrs()?
        .next()
        .ok_or_else(|| Error::protocol(format!("cannot resolve {host}")))?;
    let mut stream = TcpStream::connect_timeout(&addr, timeout)?;
    stream.set_read_timeout(Some(timeout))?;
    stream.set_write_timeout(Some(timeout))?;
    let body = call_body(method, params);
    let request = format!(
        "POST /RPC2 HTTP/1.1\r\nHost: {host}:{port}\r\nUser-Agent: rover\r\nContent-Type: text/xml\r\nContent-Length: {}\r\nConnection: close\r\n\r\n{body}",
        body.len()
    );
    stream.write_all(request.as_bytes())?;
    let mut reader = BufReader::new(stream);
    let (status, body) = read_http(&mut reader)?;
    if !status.contains(" 200") {
        return Err(Error::protocol(format!("{uri} answered {status}")));
    }
    parse_response(&body)
}

/// Calls a ROS API method and unpacks its `[code, status, value]` reply: the value when the
/// code is 1, else an error with the status text.
pub fn ros_call(uri: &str, method: &str, params: &[Value], timeout: Duration) -> Result<Value> {
    let reply = call(uri, method, params, timeout)?;
    match reply.as_array() {
        Some([code, status, value]) => {
            if code.as_int() == Some(1) {
                Ok(value.clone())
            } else {
                Err(Error::Api {
                    method: method.to_owned(),
                    status: status.as_str().unwrap_or("").to_owned(),
                })
            }
        }
        _ => Err(Error::protocol(format!(
            "{method} returned {reply:?}, not [code, status, value]"
        ))),
    }
}

/// Writes an HTTP response carrying `body` and closes nothing (the caller drops the stream).
pub fn write_response<W: Write>(out: &mut W, body: &str) -> std::io::Result<()> {
    write!(
        out,
        "HTTP/1.0 200 OK\r\nServer: rover\r\nContent-Type: text/xml\r\nContent-Length: {}\r\nConnection: close\r\n\r\n{body}",
        body.len()
    )?;
    out.flush()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_call_round_trips() -> Result<()> {
        let params = vec![
            Value::from("/rover"),
            Value::from("/a<b>&c"),
            Value::Array(vec![Value::Array(vec![Value::from("TCPROS")])]),
            Value::Int(-3),
            Value::Bool(true),
            Value::Double(0.25),
        ];
        let body = call_body("requestTopic", &params);
        let (method, back) = parse_call(&body)?;
        assert_eq!(method, "requestTopic");
        assert_eq!(back, params);
        Ok(())
    }

    #[test]
    fn responses_and_faults_parse() -> Result<()> {
        let v = Value::Array(vec![
            Value::Int(1),
            Value::from("ok"),
            Value::Struct(vec![("x".into(), Value::Int(2))]),
        ]);
        assert_eq!(parse_response(&response_body(&v))?, v);
        assert!(parse_response(&fault_body(1, "nope")).is_err());
        // Untyped values are strings (Python's xmlrpc writes them for str).
        let untyped =
            "<methodResponse><params><param><value>hi</value></param></params></methodResponse>";
        assert_eq!(parse_response(untyped)?, Value::from("hi"));
        assert!(parse_response("<methodResponse>").is_err());
        Ok(())
    }

    #[test]
    fn uris_split_into_host_and_port() -> Result<()> {
        assert_eq!(
            host_port("http://127.0.0.1:11311/")?,
            ("127.0.0.1".to_owned(), 11311)
        );
        assert_eq!(host_port("http://robot:4000")?, ("robot".to_owned(), 4000));
        assert!(host_port("ftp://x:1").is_err());
        assert!(host_port("http://x/").is_err());
        Ok(())
    }
}
