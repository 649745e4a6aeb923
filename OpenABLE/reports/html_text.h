// Text of the HTML report's parts (html_report.h, html_explorer.h): escaping and the base64 of
// its data URIs.
#pragma once

#include <string>

namespace openable {

// Base64 (RFC 4648), with padding.
std::string Base64(const std::string& bytes);

// `text` with & < > " ' escaped, for HTML text and attribute values. The page declares UTF-8:
// text that is not valid UTF-8 (a file name in another encoding) is first shown by the rule of
// every text output (ToValidUtf8, base/strings.h: each byte outside a well-formed sequence as
// \xNN); valid text is escaped as it is.
std::string HtmlEscape(const std::string& text);

// JSON text made safe inside a <script> element: < > & (which JSON has only inside strings)
// become \u003c \u003e \u0026, the same strings to a JSON reader, so that no "</script>" or
// "<!--" in a frame name or label changes how the page is parsed.
std::string ScriptSafe(std::string json_text);

}  // namespace openable
