// libFuzzer target: any bytes as a sweep's --where expression over the fields of an analysis.
// Either a WhereError pointing inside the text, or a filter that answers for a few items.
#include <cstddef>
#include <cstdint>
#include <string>

#include "sweep/where.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using flexure::sweep::Json;
  static const std::vector<std::string> fields = {"rigid", "inf_rigid", "stress_dim", "nontrivial_inf_flexes",
                                                  "second_order", "second_order.stress_margin", "title"};
  static const Json items[] = {
      Json::parse(R"({"rigid": "flexible", "inf_rigid": false, "stress_dim": 1, "nontrivial_inf_flexes": 2,
                      "second_order": {"stress_margin": 0.5}, "title": "t"})"),
      Json::parse(R"({"rigid": "rigid", "inf_rigid": true, "stress_dim": 0, "second_order": {"stress_margin": null}})"),
      Json::parse(R"({"status": "error"})")};
  const std::string text(reinterpret_cast<const char*>(data), size);
  try {
    const flexure::sweep::Where w(text, fields);
    for (const Json& j : items) (void)w(j);
  } catch (const flexure::sweep::WhereError& e) {
    if (e.offset > size) __builtin_trap();
  }
  return 0;
}
