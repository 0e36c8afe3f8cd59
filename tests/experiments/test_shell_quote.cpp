// shell_quote (experiments/shell_quote.hpp): /bin/sh reads each quoted word back as the text it
// quotes, whatever characters it holds; quoting without the quote's escape (the planted fault)
// splits a word with a quote in it.
#include <catch2/catch.hpp>

#include <cstdio>
#include <string>

#include "handcentric/experiments/shell_quote.hpp"

using handcentric::experiments::shell_quote;

namespace {

// What `sh -c 'printf %s WORD'` prints for the quoted word.
std::string printed_by_sh(const std::string& word) {
  const std::string command = "printf %s " + word;
  std::FILE* pipe = popen(("sh -c " + shell_quote(command)).c_str(), "r");
  REQUIRE(pipe != nullptr);
  std::string out;
  char buffer[256];
  for (std::size_t n; (n = std::fread(buffer, 1, sizeof(buffer), pipe)) > 0;) out.append(buffer, n);
  pclose(pipe);
  return out;
}

}  // namespace

TEST_CASE("shell_quote_gives_sh_back_the_text_it_quotes", "[unit]") {
  CHECK(shell_quote("a b") == "'a b'");
  CHECK(shell_quote("it's") == "'it'\\''s'");
  CHECK(shell_quote("") == "''");
  for (const std::string text : {"plain", "two words", "it's", "$HOME `id` \"x\" \\n *", "''"})
    CHECK(printed_by_sh(shell_quote(text)) == text);
  // The planted fault: single quotes alone end the word at the text's own quote.
  CHECK(printed_by_sh("'it's'") != "it's");
}
