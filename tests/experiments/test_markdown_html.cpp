// The report page's HTML (experiments/markdown_html.hpp): each supported construct, and no way
// for a report's text to become markup.
#include <catch2/catch.hpp>

#include "handcentric/experiments/markdown_html.hpp"

using namespace handcentric::experiments;
using Catch::Matchers::Contains;

TEST_CASE("markdown_html_renders_headings_tables_lists_code_and_images", "[unit]") {
  const std::string html = markdown_to_html(
      "# Title\n\nSome `code` here\nand more.\n\n## Table\n\n| a | b |\n|---|---|\n| 1 | 2 |\n\n- "
      "one\n- two\n\n"
      "```\nx < y\n  kept\n```\n![Fig. 3](fig3.png)\n",
      "the page");
  CHECK_THAT(html, Contains("<title>the page</title>"));
  CHECK_THAT(html, Contains("<h1>Title</h1>"));
  CHECK_THAT(html, Contains("<p>Some <code>code</code> here and more.</p>"));
  CHECK_THAT(html, Contains("<h2>Table</h2>"));
  CHECK_THAT(html, Contains("<tr><th>a</th><th>b</th></tr>\n<tr><td>1</td><td>2</td></tr>"));
  CHECK_THAT(html, Contains("<ul>\n<li>one</li>\n<li>two</li>\n</ul>"));
  CHECK_THAT(html, Contains("<pre>x &lt; y\n  kept\n</pre>"));
  CHECK_THAT(html, Contains("<img src=\"fig3.png\" alt=\"Fig. 3\">"));
}

TEST_CASE("markdown_html_escapes_every_text_so_no_markup_gets_in", "[unit]") {
  const std::string html = markdown_to_html(
      "<script>alert(1)</script>\n\n| <b> | x |\n|---|---|\n\n```\n</pre><script>\n```\n"
      "![a\"b](x.png\" onerror=\"alert(1))\n`<i>` and an unmatched ` <u>\n",
      "<title>");
  CHECK_THAT(html,
             !Contains("<script>") && !Contains("<b>") && !Contains("<i>") && !Contains("<u>"));
  CHECK_THAT(html, !Contains("\" onerror"));
  CHECK_THAT(html, Contains("&lt;script&gt;alert(1)&lt;/script&gt;"));
  CHECK_THAT(html, Contains("<title>&lt;title&gt;</title>"));
  CHECK_THAT(html, Contains("` &lt;u&gt;"));
  CHECK(html_escape("a&b'\"") == "a&amp;b&#39;&quot;");
}
