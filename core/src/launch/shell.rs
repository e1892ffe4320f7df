//! Splitting a command line into words as Python's `shlex.split` does (roslaunch splits node
//! `args`, `launch-prefix` and `command` params with it).

/// Python's `shlex.split` (POSIX mode): words split on spaces, with '...', "..." and `\`.
pub fn shell_split(s: &str) -> Result<Vec<String>, String> {
    let mut words = Vec::new();
    let mut word = String::new();
    let mut in_word = false;
    let mut chars = s.chars();
    while let Some(c) = chars.next() {
        match c {
            c if c.is_whitespace() => {
                if in_word {
                    words.push(std::mem::take(&mut word));
                    in_word = false;
                }
            }
            '\'' => {
                in_word = true;
                loop {
                    match chars.next() {
                        Some('\'') => break,
                        Some(c) => word.push(c),
                        None => return Err(format!("no closing quotation in \"{s}\"")),
                    }
                }
            }
            '"' => {
                in_word = true;
                loop {
                    match chars.next() {
                        Some('"') => break,
                        Some('\\') => match chars.next() {
                            Some(c @ ('"' | '\\' | '$' | '`')) => word.push(c),
                            Some(c) => {
                                word.push('\\');
                                word.push(c);
                            }
                            None => return Err(format!("no closing quotation in \"{s}\"")),
                        },
                        Some(c) => word.push(c),
                        None => return Err(format!("no closing quotation in \"{s}\"")),
                    }
                }
            }
            '\\' => {
                in_word = true;
                match chars.next() {
                    Some(c) => word.push(c),
                    None => return Err(format!("no escaped character in \"{s}\"")),
                }
            }
            c => {
                in_word = true;
                word.push(c);
            }
        }
    }
    if in_word {
        words.push(word);
    }
    Ok(words)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn shell_words_split_like_shlex() {
        assert_eq!(
            shell_split(r#"xacro --inorder '/a b/robot.xacro' x:="1 2" y:=\$z"#),
            Ok(vec![
                "xacro".to_owned(),
                "--inorder".to_owned(),
                "/a b/robot.xacro".to_owned(),
                "x:=1 2".to_owned(),
                "y:=$z".to_owned()
            ])
        );
        assert!(shell_split("'open").is_err());
    }
}
