// The names of lightning's enums as the HTTP API spells them, both ways: one table per enum.
#include <array>
#include <utility>

#include "effects/lightning.h"

namespace effects::lightning {
namespace {

constexpr std::array<std::pair<Method, const char*>, 3> kMethods{
    {{Method::kFast, "fast"}, {Method::kDbm, "dbm"}, {Method::kCharges, "charges"}}};
constexpr std::array<std::pair<Solver, const char*>, 3> kSolvers{
    {{Solver::kMgpcg, "mgpcg"}, {Solver::kCg, "cg"}, {Solver::kCapacitance, "capacitance"}}};
constexpr std::array<std::pair<Guide, const char*>, 3> kGuides{
    {{Guide::kAuto, "auto"}, {Guide::kAstar, "astar"}, {Guide::kNone, "none"}}};

template <class E, size_t N>
const char* nameOf(const std::array<std::pair<E, const char*>, N>& table, E value) {
  for (const auto& [e, name] : table)
    if (e == value) return name;
  return "?";
}

template <class E, size_t N>
std::optional<E> valueOf(const std::array<std::pair<E, const char*>, N>& table, std::string_view name) {
  for (const auto& [e, n] : table)
    if (name == n) return e;
  return std::nullopt;
}

}  // namespace

const char* toString(Method m) { return nameOf(kMethods, m); }
const char* toString(Solver s) { return nameOf(kSolvers, s); }
const char* toString(Guide g) { return nameOf(kGuides, g); }
std::optional<Method> parseMethod(std::string_view name) { return valueOf(kMethods, name); }
std::optional<Solver> parseSolver(std::string_view name) { return valueOf(kSolvers, name); }
std::optional<Guide> parseGuide(std::string_view name) { return valueOf(kGuides, name); }

}  // namespace effects::lightning
