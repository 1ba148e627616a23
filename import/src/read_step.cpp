// STEP (AP203/AP214/AP242) into an XCAF document: read_step runs one attempt after another, each in
// an isolated child (step_attempt.h), until one gives faces or none is left.
#include "cad_transfer.h"
#include "isolated_run.h"
#include "readers.h"
#include "step_attempt.h"
#include "step_parallel_transfer.h"

#include <omp.h>

#include <algorithm>
#include <optional>
#include <set>
#include <string>
#include <unordered_set>
#include <utility>
#include <vector>

namespace cadclash::detail {

// OCCT's translators dereference the missing parameters of malformed entities (StepToGeom::MakeLine
// on a LINE whose point was cut off), so each attempt runs in a child process, which sends back the
// transferred document (cad_transfer.h): a crash there costs the attempt, not the caller's process,
// and this process never runs OCCT's STEP code on the file.
ImportResult read_step(const std::string& path, const ImportOptions& options, const std::string* text) {
  prepare_occt_exchange();
  const TransferHealing healing(options.transfer_healing);
  std::vector<Diagnostic> notes;  // how the attempts went, first in the result
  std::optional<Transfer> faceless;  // the first attempt that finished without a face
  double read_seconds = 0.0;         // parsing, over every attempt that finished
  auto finish = [&](Transfer transfer) {
    transfer.read_seconds = read_seconds;
    // What the faceless attempt said (its transfer's checks) stays, without repeating what this one says.
    if (faceless) {
      std::unordered_set<std::string> said;
      for (const Diagnostic& d : transfer.diagnostics) said.insert(format_diagnostic(d));
      for (const Diagnostic& d : faceless->diagnostics)
        if (!said.count(format_diagnostic(d))) notes.push_back(d);
    }
    ImportResult result = finish_transfer(std::move(transfer), path, options);
    for (const Diagnostic& d : notes) result.complete = result.complete && d.severity != Severity::Error;
    result.diagnostics.insert(result.diagnostics.begin(), notes.begin(), notes.end());
    return result;
  };
  // Workers are forked from the isolated reader's child, which has one thread; an unisolated reader
  // runs in this process, which may have many, and never forks.
  const std::size_t workers = !options.isolate_cad_readers ? 1
                              : options.transfer_workers > 0 ? static_cast<std::size_t>(options.transfer_workers)
                                                             : static_cast<std::size_t>(std::max(1, omp_get_max_threads()));
  const std::size_t min_bytes = options.transfer_workers > 0 ? 0 : kParallelReadMinBytes;
  bool split = true;  // cut the text into pieces; off once a piece failed

  Attempt attempt = Attempt::Whole;
  std::set<std::int64_t> skip;  // face entities a child crashed on, each one
  constexpr std::size_t kMaxSkips = 20;
  const ReaderClock clock(options.reader_time_limit_seconds);
  if (auto warning = unapplied_time_limit(path, options)) notes.push_back(*warning);
  for (;;) {
    IsolatedTransfer run = transfer_in_child(path, options.isolate_cad_readers, clock.left(),
                                             [&](const Mark& mark) { return read_step_attempt(path, {attempt, mark, &skip, workers, min_bytes, split, options.cache_dir, text}); });
    if (run.warning) notes.push_back(*run.warning);
    const ChildRun& child = run.child;
    read_seconds += run.transfer.read_seconds;
    if (!child.crashed && run.transfer.split_failed) {
      split = false;
      continue;
    }
    const bool parsed = child.marks.find(kParsed) != std::string::npos;
    if (!child.crashed) {
      if (child.marks.find(kShapes) != std::string::npos) return finish(std::move(run.transfer));
      const bool loose = attempt == Attempt::LooseFaces || child.marks.find(kLoose) != std::string::npos;
      if (!faceless) faceless.emplace(std::move(run.transfer));
      if (loose || !parsed) break;
      // OCCT made nothing of the products: each face entity on its own may still give some.
      notes.push_back({Severity::Error, path, 0, -1,
                       attempt == Attempt::Whole
                           ? "the file's products gave no face; read again as loose faces"
                           : "without the faces that reach entities OCCT could not read whole, no face was left; read again as loose faces"});
      attempt = Attempt::LooseFaces;
      continue;
    }
    const char* stage = !parsed ? "parsing the file"
                        : attempt == Attempt::LooseFaces ? "transferring its faces one by one"
                        : attempt == Attempt::Whole ? "transferring its shapes"
                                                    : "transferring its shapes without the broken faces";
    const std::int64_t in_progress = entity_in_progress(child.marks);
    if (child.timed_out) {
      // Another attempt would meet the same slow entity: what earlier attempts made is all there is.
      notes.push_back({Severity::Error, path, 0, in_progress, clock.stopped_message(stage, in_progress)});
      break;
    }
    if (attempt == Attempt::LooseFaces && in_progress >= 0 && skip.size() < kMaxSkips && skip.insert(in_progress).second) {
      notes.push_back({Severity::Error, path, 0, in_progress,
                       "OCCT crashed with " + child.how + " while transferring this face entity on its own (in an isolated reader); dropped"});
      continue;
    }
    const char* next = !parsed || attempt == Attempt::LooseFaces ? "nothing more could be read"
                       : attempt == Attempt::Whole ? "read again without the faces that reach entities it could not read whole"
                                                   : "read again as loose faces";
    notes.push_back({Severity::Error, path, 0, -1,
                     std::string("OCCT crashed with ") + child.how + " while " + stage + " (in an isolated reader); " + next});
    if (!parsed || attempt == Attempt::LooseFaces) break;
    attempt = attempt == Attempt::Whole ? Attempt::WithoutBrokenFaces : Attempt::LooseFaces;
  }
  if (faceless) {
    Transfer best = std::move(*faceless);
    faceless.reset();
    return finish(std::move(best));
  }
  Transfer nothing;
  nothing.complete = false;
  nothing.diagnostics.push_back({Severity::Error, path, 0, -1, "no shape could be read from the STEP file"});
  return finish(std::move(nothing));
}

}  // namespace cadclash::detail
