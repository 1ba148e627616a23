// Shared pieces of the mesh readers (OBJ, OFF, assimp formats) and the exporters. Internal.
#pragma once

#include "cadclash/import.h"

#include <cstddef>
#include <cstdint>
#include <map>
#include <span>
#include <string>
#include <string_view>
#include <vector>

namespace cadclash::detail {

// Reads a whole file into `out`. On failure returns false and sets `error` to one sentence.
bool read_whole_file(const std::string& path, std::string& out, std::string& error);

// The file name without directory and extension: the part name of a single-part mesh file.
std::string file_stem(const std::string& path);

// Splits `text` into lines ("\n", "\r\n" or "\r" endings), numbered from 1.
class LineReader {
 public:
  explicit LineReader(std::string_view text) : text_(text) {}
  // Returns false at the end of the text; otherwise the next line without its ending.
  bool next(std::string_view& line);
  std::int64_t line_number() const { return line_; }  // of the line last returned

 private:
  std::string_view text_;
  std::size_t pos_ = 0;
  std::int64_t line_ = 0;
};

// Splits a line into whitespace-separated tokens.
void split_tokens(std::string_view line, std::vector<std::string_view>& tokens);

// How a reader says that a value is past cadclash::kMaxLength (model.h): "outside the supported
// range (magnitude <= 2^128, about 3.4e38 mm)".
extern const std::string kOutsideRange;
// A double as a diagnostic shows it ("%.17g").
std::string printable_number(double x);

enum class NumberStatus { Ok, Invalid, NotFinite };
// Parses the whole token as a double ("1", "-2.5e3", "nan", "inf", "1e999" → NotFinite).
NumberStatus parse_double(std::string_view token, double& value);
// Parses the whole token as a signed integer.
bool parse_int(std::string_view token, std::int64_t& value);

// True if the text holds a byte no text mesh format uses (NUL or another control character).
// Sets `line` to the 1-based line of the first one.
bool find_binary_byte(std::string_view text, std::int64_t& line);

// A token from the file as it may be quoted in a message: at most its first 32 bytes, with every byte
// outside printable ASCII written as \xNN, so messages stay valid UTF-8 (the JSON report needs it).
std::string printable_token(std::string_view token);
// The same escaping for a whole text, without the length limit: for names from the file and for
// library messages (assimp's) that quote the file's bytes.
std::string printable_text(std::string_view text);

// Collects diagnostics, listing at most `cap` per category and summarising the rest, so a file
// with a million bad faces gives a readable report that still counts everything dropped.
class DiagnosticCollector {
 public:
  DiagnosticCollector(std::string file, std::size_t cap = 20) : file_(std::move(file)), cap_(cap) {}
  // `category` is a plural noun phrase used in the summary ("faces dropped").
  void add(Severity severity, std::int64_t line, const std::string& category, std::string message);
  // Appends everything, with one "... and N more <category>" line per category over the cap.
  void flush_into(std::vector<Diagnostic>& out);
  bool any_error() const { return errors_ > 0; }

 private:
  struct Category {
    std::size_t listed = 0;
    std::size_t unlisted = 0;
    Severity severity = Severity::Warning;
  };
  std::string file_;
  std::size_t cap_;
  std::size_t errors_ = 0;
  std::vector<Diagnostic> listed_;
  std::map<std::string, Category> categories_;
};

// Why a face with these corner positions (in order) is degenerate, as a phrase: "has a zero-length
// edge (corners 1 and 2 are the same point)" or "has zero area (its corners are collinear)"; empty
// when it is neither. Exact on the stored doubles: zero area means every corner lies on the line
// through the first two. Readers keep such faces and warn: a degenerate triangle is a
// segment or point that can still touch another surface, and dropping it would renumber triangles.
std::string degenerate_face(std::span<const Vec3> corners);

// Renumbers a surface's vertices in the order of their numbers in the source file, given the
// source number of each vertex (source_of_local[i] for mesh.vertices[i]), so a mesh read back keeps
// the vertex order it was written with, whatever order its faces use them in.
void renumber_in_source_order(TriangleMesh& mesh, std::vector<std::uint64_t>& source_of_local);

// Finishes a one-part model read from `path`: sets part, name, source file and AABB of each surface
// (which must already carry triangles and provenance), adds the part named after the file stem and
// one identity instance "/<stem>".
void finish_single_part_model(Model& model, const std::string& path);

}  // namespace cadclash::detail
