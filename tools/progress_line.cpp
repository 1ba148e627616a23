#include "progress_line.h"

#include "cli_common.h"
#include "cmd_check_mpi.h"

#include <sys/ioctl.h>
#include <unistd.h>

#include <cmath>
#include <cstdio>
#include <iomanip>
#include <sstream>

namespace cadclash::cli {
namespace {

// Redraws at most this often (the first and last call of a run always).
constexpr auto kRedraw = std::chrono::milliseconds(100);

std::size_t terminal_width() {
  winsize w{};
  if (ioctl(fileno(stderr), TIOCGWINSZ, &w) == 0 && w.ws_col > 10) return w.ws_col;
  return 80;
}

std::string duration_text(double seconds) {
  const auto s = static_cast<long long>(std::llround(seconds));
  std::ostringstream os;
  if (s >= 3600) os << s / 3600 << ':' << std::setw(2) << std::setfill('0') << (s / 60) % 60;
  else os << s / 60;
  os << ':' << std::setw(2) << std::setfill('0') << s % 60;
  return os.str();
}

}  // namespace

bool show_progress(bool quiet) { return !quiet && !mpi_launch().by_mpirun && stderr_is_terminal(); }

std::string progress_text(const Progress& p, double seconds) {
  std::ostringstream os;
  switch (p.stage) {
    case ProgressStage::ReadFile: os << "reading files "; break;
    case ProgressStage::TessellatePart: os << "meshing parts "; break;
    case ProgressStage::CheckPairs: os << "checking instance pairs "; break;
    case ProgressStage::TrajectoryStep: os << "trajectory steps "; break;
    case ProgressStage::CheckPart: os << "checking parts "; break;
  }
  os << p.done << '/' << p.total;
  if (p.total > 0) os << ' ' << p.done * 100 / p.total << '%';
  if (p.stage == ProgressStage::CheckPairs && !p.label.empty()) os << " (" << p.label << ')';
  if (seconds >= 0.5 && p.done > 0) {
    const double rate = static_cast<double>(p.done) / seconds;
    os << ", " << std::fixed << std::setprecision(rate < 10.0 ? 1 : 0) << rate << "/s";
    if (p.done < p.total) os << ", " << duration_text(static_cast<double>(p.total - p.done) / rate) << " left";
  }
  if (p.stage == ProgressStage::TrajectoryStep && !p.label.empty()) os << ": step " << p.label;
  else if (p.stage != ProgressStage::CheckPairs && !p.label.empty()) os << ": " << p.label;
  return os.str();
}

ProgressLine::ProgressLine(bool shown, std::ostream& os) : shown_(shown), os_(os) {}

ProgressLine::~ProgressLine() { clear(); }

ProgressCallback ProgressLine::callback() {
  if (!shown_) return {};
  return [this](const Progress& p) { update(p); };
}

void ProgressLine::status(const std::string& text) {
  if (shown_) draw(text);
}

void ProgressLine::clear() {
  if (!drawn_) return;
  os_ << "\r\033[K" << std::flush;
  drawn_ = false;
}

void ProgressLine::update(const Progress& p) {
  const Clock::time_point now = Clock::now();
  const bool starts = p.done == 0 || p.stage != stage_ || p.total != total_;
  if (starts) {
    stage_ = p.stage;
    total_ = p.total;
    run_start_ = now;
  }
  if (p.done >= p.total) {  // a run ended: nothing of it stays on the screen
    clear();
    return;
  }
  if (!starts && now - last_draw_ < kRedraw) return;
  draw(progress_text(p, std::chrono::duration<double>(now - run_start_).count()));
}

void ProgressLine::draw(std::string text) {
  const std::size_t width = terminal_width() - 1;  // the last column would wrap on some terminals
  if (text.size() > width) text = text.substr(0, width - 3) + "...";
  os_ << "\r\033[K" << text << std::flush;
  drawn_ = true;
  last_draw_ = Clock::now();
}

}  // namespace cadclash::cli
