#include "scenes/style.h"

#include <algorithm>
#include <cctype>
#include <map>

namespace flexure::scenes {

std::optional<render::Color> parseColor(const std::string& text) {
  std::string t = text;
  std::transform(t.begin(), t.end(), t.begin(), [](unsigned char c) { return std::tolower(c); });
  if (!t.empty() && t[0] == '#' && (t.size() == 7 || t.size() == 9)) {
    unsigned v[4] = {0, 0, 0, 255};
    for (size_t i = 0; i + 1 < t.size(); i += 2) {
      const std::string byte = t.substr(i + 1, 2);
      if (!std::isxdigit(static_cast<unsigned char>(byte[0])) || !std::isxdigit(static_cast<unsigned char>(byte[1])))
        return std::nullopt;
      v[i / 2] = static_cast<unsigned>(std::stoul(byte, nullptr, 16));
    }
    return render::Color{v[0] / 255.f, v[1] / 255.f, v[2] / 255.f, v[3] / 255.f};
  }
  static const std::map<std::string, unsigned> names = {
      {"steelblue", 0x4682B4}, {"black", 0x000000}, {"white", 0xFFFFFF}, {"lightgrey", 0xD3D3D3},
      {"lightgray", 0xD3D3D3}, {"red3", 0xCD0000}, {"red", 0xFF0000}, {"green3", 0x00CD00},
      {"green", 0x008000}, {"blue", 0x0000FF}, {"grey80", 0xCCCCCC}, {"gray80", 0xCCCCCC},
      {"grey50", 0x7F7F7F}, {"gray50", 0x7F7F7F}, {"grey98", 0xFAFAFA}, {"gray98", 0xFAFAFA},
      {"gray35", 0x595959}, {"grey35", 0x595959}, {"grey", 0xBEBEBE}, {"gray", 0xBEBEBE},
      {"teal", 0x008080}, {"coral", 0xFF7F50}, {"orange", 0xFFA500}, {"purple", 0xA020F0},
      {"darkgrey", 0xA9A9A9}, {"darkgray", 0xA9A9A9}, {"gold", 0xFFD700}, {"navy", 0x000080}};
  auto it = names.find(t);
  if (it == names.end()) return std::nullopt;
  return render::Color{((it->second >> 16) & 255) / 255.f, ((it->second >> 8) & 255) / 255.f, (it->second & 255) / 255.f, 1};
}

}  // namespace flexure::scenes
