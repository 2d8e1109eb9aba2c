//! Pretty scene JSON made compact: every array of numbers rewritten onto one line.

/// Rewrites every array that holds no string, object or array onto one line.
pub(super) fn inline_number_arrays(json: &str) -> String {
    let bytes = json.as_bytes();
    let mut out = String::with_capacity(json.len());
    let (mut i, mut in_string, mut escaped) = (0, false, false);
    while i < bytes.len() {
        let b = bytes[i];
        if in_string {
            if escaped {
                escaped = false;
            } else if b == b'\\' {
                escaped = true;
            } else if b == b'"' {
                in_string = false;
            }
        } else if b == b'"' {
            in_string = true;
        } else if b == b'[' {
            let rest = &json[i + 1..];
            if let Some(end) = rest.find([']', '[', '{', '"'])
                && rest.as_bytes()[end] == b']'
            {
                let items: Vec<&str> = rest[..end]
                    .split(',')
                    .map(str::trim)
                    .filter(|s| !s.is_empty())
                    .collect();
                out.push('[');
                out.push_str(&items.join(", "));
                out.push(']');
                i += end + 2;
                continue;
            }
        }
        // Copy the whole UTF-8 character starting here.
        let len = json[i..].chars().next().map_or(1, char::len_utf8);
        out.push_str(&json[i..i + len]);
        i += len;
    }
    out
}
