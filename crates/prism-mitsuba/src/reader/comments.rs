//! Comments as Mitsuba 3 reads them. XML forbids `--` inside a comment and a comment ending
//! in `-` (`<!-- a -- b -->`, `<!-- a --->`; XML 1.0, production 15), but pugixml, Mitsuba's
//! parser, ends a comment at the first `-->` and accepts anything before it, and public scenes
//! use that. Before the strict parser sees such a file, the hyphens inside each comment are
//! blanked: byte for byte, so that every line and column stays where it was.

use std::borrow::Cow;

/// `text` with the hyphens inside every comment that XML would refuse replaced by spaces.
/// Comments are found as pugixml finds them: from `<!--` to the next `-->`, outside CDATA
/// sections and processing instructions. A comment that is never closed is left for the parser
/// to report.
pub fn tolerate_hyphens_in_comments(text: &str) -> Cow<'_, str> {
    let mut out = String::new();
    let mut copied = 0;
    let mut pos = 0;
    while let Some(found) = text[pos..].find('<') {
        let start = pos + found;
        let rest = &text[start..];
        let (open, close, comment) = if rest.starts_with("<!--") {
            ("<!--", "-->", true)
        } else if rest.starts_with("<![CDATA[") {
            ("<![CDATA[", "]]>", false)
        } else if rest.starts_with("<?") {
            ("<?", "?>", false)
        } else {
            pos = start + 1;
            continue;
        };
        let body_start = start + open.len();
        let Some(length) = text[body_start..].find(close) else {
            break;
        };
        let body_end = body_start + length;
        let body = &text[body_start..body_end];
        if comment && (body.contains("--") || body.ends_with('-')) {
            out.push_str(&text[copied..body_start]);
            out.push_str(&body.replace('-', " "));
            copied = body_end;
        }
        pos = body_end + close.len();
    }
    if copied == 0 {
        Cow::Borrowed(text)
    } else {
        out.push_str(&text[copied..]);
        Cow::Owned(out)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn only_comments_xml_refuses_change() {
        let fine = "<a><!-- a - b --><![CDATA[ -- ]]><?pi -- ?></a>";
        assert!(matches!(
            tolerate_hyphens_in_comments(fine),
            Cow::Borrowed(_)
        ));
        assert_eq!(
            tolerate_hyphens_in_comments("<a><!-- x -- y ---><b c=\"--\"/><!--z---></a>"),
            "<a><!-- x    y  --><b c=\"--\"/><!--z --></a>"
        );
    }

    #[test]
    fn hyphens_in_cdata_and_instructions_are_kept() {
        let text = "<a><![CDATA[ <!-- -- ]]><?pi <!-- -- ?><!-- -- --></a>";
        assert_eq!(
            tolerate_hyphens_in_comments(text),
            "<a><![CDATA[ <!-- -- ]]><?pi <!-- -- ?><!--    --></a>"
        );
    }

    #[test]
    fn an_unclosed_comment_is_left_alone() {
        let text = "<a><!-- -- never closed</a>";
        assert_eq!(tolerate_hyphens_in_comments(text), text);
    }

    #[test]
    fn lines_and_columns_stay_put() {
        let text = "<a>\n<!-- é -- ü\n -- --->\n<b/></a>";
        let clean = tolerate_hyphens_in_comments(text);
        assert_eq!(clean.len(), text.len());
        assert_eq!(clean.find("<b/>"), text.find("<b/>"));
        assert_eq!(clean.lines().count(), text.lines().count());
    }
}
