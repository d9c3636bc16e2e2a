#include "tests/service/mini_yaml.h"

#include <sstream>

namespace tod::server::testing {
namespace {

struct Line {
  int indent = 0;
  std::string text;  // without indentation and trailing spaces/comments
  int number = 0;    // 1-based, for messages
};

std::string StripComment(const std::string& text) {
  bool single = false, dbl = false;
  for (size_t i = 0; i < text.size(); ++i) {
    const char c = text[i];
    if (c == '\'' && !dbl) single = !single;
    if (c == '"' && !single) dbl = !dbl;
    if (c == '#' && !single && !dbl && (i == 0 || text[i - 1] == ' ')) return text.substr(0, i);
  }
  return text;
}

std::string TrimRight(std::string text) {
  while (!text.empty() && (text.back() == ' ' || text.back() == '\r')) text.pop_back();
  return text;
}

std::string Unquote(const std::string& text) {
  if (text.size() >= 2 && ((text.front() == '"' && text.back() == '"') ||
                           (text.front() == '\'' && text.back() == '\''))) {
    return text.substr(1, text.size() - 2);
  }
  return text;
}

YamlNode Scalar(const std::string& text) {
  YamlNode node;
  if (text == "null" || text == "~") return node;
  node.kind = YamlNode::Kind::kScalar;
  node.scalar = Unquote(text);
  return node;
}

// Finds the ": " (or final ':') that ends a mapping key outside quotes; npos if none.
size_t KeyColon(const std::string& text) {
  if (text.empty() || text[0] == '"' || text[0] == '\'' || text[0] == '[' || text[0] == '{') {
    if (!text.empty() && (text[0] == '"' || text[0] == '\'')) {
      const size_t close = text.find(text[0], 1);
      if (close != std::string::npos && close + 1 < text.size() && text[close + 1] == ':') {
        return close + 1;
      }
    }
    return std::string::npos;
  }
  for (size_t i = 0; i < text.size(); ++i) {
    if (text[i] == ':' && (i + 1 == text.size() || text[i + 1] == ' ')) return i;
  }
  return std::string::npos;
}

class Parser {
 public:
  explicit Parser(std::vector<Line> lines) : lines_(std::move(lines)) {}

  Result<YamlNode> Document() {
    if (lines_.empty()) return YamlNode{};
    Result<YamlNode> node = Block(lines_[0].indent);
    if (!node.ok()) return node;
    if (at_ < lines_.size()) return Error("unexpected indentation");
    return node;
  }

 private:
  Status Error(const std::string& what) const {
    const int number = at_ < lines_.size() ? lines_[at_].number : -1;
    return Status::InvalidArgument("yaml line " + std::to_string(number) + ": " + what);
  }
  static bool IsItem(const std::string& text) { return text == "-" || text.rfind("- ", 0) == 0; }

  Result<YamlNode> Block(int indent) {
    if (IsItem(lines_[at_].text)) return Sequence(indent);
    return Mapping(indent);
  }

  Result<YamlNode> Value(const std::string& text, int parent_indent) {
    if (text == "|" || text == "|-" || text == ">" || text == ">-" || text == "|+") {
      YamlNode node;
      node.kind = YamlNode::Kind::kScalar;
      while (at_ < lines_.size() && lines_[at_].indent > parent_indent) {
        node.scalar += lines_[at_++].text + "\n";
      }
      return node;
    }
    if (text.size() >= 2 && text.front() == '[' && text.back() == ']') {
      YamlNode node;
      node.kind = YamlNode::Kind::kSeq;
      std::stringstream items(text.substr(1, text.size() - 2));
      std::string item;
      while (std::getline(items, item, ',')) {
        const size_t first = item.find_first_not_of(' ');
        if (first == std::string::npos) continue;
        node.items.push_back(Scalar(TrimRight(item.substr(first))));
      }
      return node;
    }
    if (text == "{}") {
      YamlNode node;
      node.kind = YamlNode::Kind::kMap;
      return node;
    }
    return Scalar(text);
  }

  Result<YamlNode> Mapping(int indent) {
    YamlNode node;
    node.kind = YamlNode::Kind::kMap;
    while (at_ < lines_.size() && lines_[at_].indent == indent && !IsItem(lines_[at_].text)) {
      const std::string text = lines_[at_].text;
      const size_t colon = KeyColon(text);
      if (colon == std::string::npos) return Error("expected 'key: value'");
      const std::string key = Unquote(text.substr(0, colon));
      const std::string rest = colon + 1 < text.size() ? text.substr(colon + 2) : "";
      ++at_;
      YamlNode value;
      if (!rest.empty()) {
        Result<YamlNode> parsed = Value(rest, indent);
        if (!parsed.ok()) return parsed;
        value = std::move(*parsed);
      } else if (at_ < lines_.size() &&
                 (lines_[at_].indent > indent ||
                  (lines_[at_].indent == indent && IsItem(lines_[at_].text)))) {
        Result<YamlNode> parsed = Block(lines_[at_].indent);
        if (!parsed.ok()) return parsed;
        value = std::move(*parsed);
      }
      node.entries.emplace_back(key, std::move(value));
    }
    if (at_ < lines_.size() && lines_[at_].indent > indent) return Error("unexpected indentation");
    return node;
  }

  Result<YamlNode> Sequence(int indent) {
    YamlNode node;
    node.kind = YamlNode::Kind::kSeq;
    while (at_ < lines_.size() && lines_[at_].indent == indent && IsItem(lines_[at_].text)) {
      const std::string rest = lines_[at_].text == "-" ? "" : lines_[at_].text.substr(2);
      if (rest.empty()) {
        ++at_;
        if (at_ < lines_.size() && lines_[at_].indent > indent) {
          Result<YamlNode> item = Block(lines_[at_].indent);
          if (!item.ok()) return item;
          node.items.push_back(std::move(*item));
        } else {
          node.items.emplace_back();
        }
      } else if (KeyColon(rest) != std::string::npos || IsItem(rest)) {
        // "- key: v": the item is a block that starts on this line, two columns further in.
        lines_[at_].indent = indent + 2;
        lines_[at_].text = rest;
        Result<YamlNode> item = Block(indent + 2);
        if (!item.ok()) return item;
        node.items.push_back(std::move(*item));
      } else {
        ++at_;
        Result<YamlNode> item = Value(rest, indent);
        if (!item.ok()) return item;
        node.items.push_back(std::move(*item));
      }
    }
    return node;
  }

  std::vector<Line> lines_;
  size_t at_ = 0;
};

}  // namespace

const YamlNode* YamlNode::Get(const std::string& key) const {
  for (const auto& [name, value] : entries) {
    if (name == key) return &value;
  }
  return nullptr;
}

const YamlNode* YamlNode::Path(const std::string& dotted) const {
  const YamlNode* node = this;
  std::stringstream steps(dotted);
  std::string step;
  while (node != nullptr && std::getline(steps, step, '.')) node = node->Get(step);
  return node;
}

std::string YamlNode::Str(const std::string& dotted, const std::string& fallback) const {
  const YamlNode* node = Path(dotted);
  return node != nullptr && node->kind == Kind::kScalar ? node->scalar : fallback;
}

Result<std::vector<YamlNode>> ParseYamlDocuments(const std::string& text) {
  std::vector<YamlNode> documents;
  std::vector<Line> lines;
  auto flush = [&]() -> Status {
    if (lines.empty()) return Status::Ok();
    Result<YamlNode> document = Parser(std::move(lines)).Document();
    lines.clear();
    if (!document.ok()) return document.status();
    documents.push_back(std::move(*document));
    return Status::Ok();
  };
  std::stringstream stream(text);
  std::string raw;
  int number = 0;
  while (std::getline(stream, raw)) {
    ++number;
    if (raw.rfind("---", 0) == 0) {
      if (Status s = flush(); !s.ok()) return s;
      continue;
    }
    const std::string content = TrimRight(StripComment(raw));
    const size_t first = content.find_first_not_of(' ');
    if (first == std::string::npos) continue;
    lines.push_back({static_cast<int>(first), content.substr(first), number});
  }
  if (Status s = flush(); !s.ok()) return s;
  return documents;
}

}  // namespace tod::server::testing
