"""scripts/check_function_length.py: the C++ scan finds function bodies (members, constructors with
initializer lists, operators) and nothing else (namespaces, classes, initializers), and measures
them as the Python ast measures a def."""

from __future__ import annotations

import importlib.util
from pathlib import Path

_SCRIPT = Path(__file__).resolve().parents[2] / "scripts" / "check_function_length.py"
_spec = importlib.util.spec_from_file_location("check_function_length", _SCRIPT)
checker = importlib.util.module_from_spec(_spec)
_spec.loader.exec_module(checker)

CPP = """\
#include <vector>
namespace farlio::map {
namespace {
constexpr int kTable[] = {1, 2, 3};
const auto twice = [](int x) { return 2 * x; };
}  // namespace

struct Point : Base {
  int x = 0;
  bool operator==(const Point& o) const { return x == o.x; }
};

Map::Map(const Config& c) : config_(c), keys_{1, 2} {
  // a comment with a brace {
  const char* text = "also { here";
  for (auto k : keys_) {
    if (k) {
      use([&](int i) { return i; });
    }
  }
}

template <typename T>
T Map::get(std::size_t i) const
{
  return T{};
}
}  // namespace farlio::map
"""


def test_cpp_functions_are_found_with_their_lines():
    found = {name: (first, lines) for name, first, lines in checker.cpp_functions(CPP)}
    assert found == {"operator==": (10, 1), "Map::Map": (13, 21 - 13 + 1), "Map::get": (23, 27 - 23 + 1)}


def test_python_functions_are_measured_from_def_to_last_line():
    text = "def f(x):\n    def g():\n        return 1\n\n    return g() + x\n"
    assert sorted(checker.python_functions(text)) == [("f", 1, 5), ("g", 2, 2)]


def test_comments_strings_and_preprocessor_lines_are_blanked_keeping_lines():
    text = "#define X {\\\n  }\nint a = 1; // {\nconst char* s = \"}\"; char c = '{';\n"
    blanked = checker.blank_cpp(text)
    assert blanked.count("\n") == text.count("\n")
    assert "{" not in blanked and "}" not in blanked


def test_an_access_label_is_not_counted_as_the_next_function():
    text = "class C {\n public:\n  void f() {\n    g();\n  }\n};\n"
    assert checker.cpp_functions(text) == [("f", 3, 3)]
