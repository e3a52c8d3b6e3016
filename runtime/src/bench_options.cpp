#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstdlib>
#include <stdexcept>

#include "avs/bench/report.hpp"

namespace avs::bench {

namespace {

std::string shown(double v) {
  std::string text = std::to_string(v);
  text.erase(text.find_last_not_of('0') + 1);
  if (!text.empty() && text.back() == '.') text.pop_back();
  return text;
}

}  // namespace

Options::Options(std::string bench, const std::vector<std::string>& args,
                 const std::vector<std::string>& flags)
    : bench_(std::move(bench)) {
  const std::vector<std::string> words = option_words(args);
  for (std::size_t i = 0; i < words.size(); ++i) {
    if (words[i] == "--help" || words[i] == "-h" ||
        std::find(flags.begin(), flags.end(), words[i]) != flags.end()) {
      given_[words[i]] = "";
      used_[words[i]] = false;
      continue;
    }
    if (words[i].rfind("--", 0) != 0) {
      throw std::invalid_argument("avs bench " + bench_ +
                                  ": expected an option (--name value), got '" + words[i] + "'");
    }
    if (i + 1 >= words.size()) {
      throw std::invalid_argument("avs bench " + bench_ + ": " + words[i] + " needs a value");
    }
    given_[words[i]] = words[i + 1];
    used_[words[i]] = false;
    ++i;
  }
}

const std::string* Options::value(const std::string& key) {
  asked_.push_back(key);
  auto it = given_.find(key);
  if (it == given_.end()) return nullptr;
  used_[key] = true;
  return &it->second;
}

void Options::refuse(const std::string& key, const std::string& wanted,
                     const std::string& got) const {
  throw std::invalid_argument("avs bench " + bench_ + ": " + key + " wants " + wanted + ", got '" +
                              got + "'");
}

double Options::number(const std::string& key, double fallback, double min, double max) {
  const std::string wanted = "a number in [" + shown(min) + ", " + shown(max) + "]";
  help_.push_back(key + " N  " + wanted + " (default " + shown(fallback) + ")");
  const std::string* text = value(key);
  if (text == nullptr) return fallback;
  errno = 0;
  char* end = nullptr;
  const double v = std::strtod(text->c_str(), &end);
  if (text->empty() || end != text->c_str() + text->size() || errno == ERANGE ||
      !std::isfinite(v) || v < min || v > max) {
    refuse(key, wanted, *text);
  }
  return v;
}

long long Options::integer(const std::string& key, long long fallback, long long min,
                           long long max) {
  const std::string wanted =
      "an integer in [" + std::to_string(min) + ", " + std::to_string(max) + "]";
  help_.push_back(key + " N  " + wanted + " (default " + std::to_string(fallback) + ")");
  const std::string* text = value(key);
  if (text == nullptr) return fallback;
  errno = 0;
  char* end = nullptr;
  const long long v = std::strtoll(text->c_str(), &end, 10);
  if (text->empty() || end != text->c_str() + text->size() || errno == ERANGE || v < min ||
      v > max) {
    refuse(key, wanted, *text);
  }
  return v;
}

bool Options::flag(const std::string& key) {
  if (key != "--help" && key != "-h") help_.push_back(key + "  a flag");
  return value(key) != nullptr;
}

std::string Options::text(const std::string& key, std::string fallback) {
  help_.push_back(key + " TEXT" +
                  (fallback.empty() ? std::string() : "  (default " + fallback + ")"));
  const std::string* text = value(key);
  return text == nullptr ? std::move(fallback) : *text;
}

void Options::finish() const {
  const auto unanswered = [&](const char* key) {
    const auto it = used_.find(key);
    return it != used_.end() && !it->second;
  };
  if (unanswered("--help") || unanswered("-h")) {
    std::string text = "avs bench " + bench_ + " options (as --key value or --key=value):\n";
    for (const std::string& line : help_) {
      const std::size_t gap = line.find("  ");
      text += "  " + line.substr(0, gap);
      if (gap != std::string::npos) {
        text += std::string(gap < 28 ? 28 - gap : 1, ' ') + line.substr(gap + 2);
      }
      text += "\n";
    }
    if (help_.empty()) text += "  (none)\n";
    throw HelpRequested(text);
  }
  std::string unknown;
  for (const auto& [key, used] : used_) {
    if (!used) unknown += (unknown.empty() ? "" : ", ") + key;
  }
  if (unknown.empty()) return;
  std::string known;
  for (const auto& key : asked_) known += (known.empty() ? "" : ", ") + key;
  throw std::invalid_argument("avs bench " + bench_ + ": unknown option " + unknown +
                              (known.empty() ? std::string() : " (expected " + known + ")"));
}

}  // namespace avs::bench
