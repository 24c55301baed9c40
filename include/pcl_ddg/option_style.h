#pragma once
/** \file
 * How a front end spells options in its messages, so that the library's checks (fit_choices.h,
 * massTypeNamed, solverNamed, normalWeightingNamed, chooseOperator) word an error once and every
 * front end names the options as its users type them: the tools `-neighbours rings`, Python
 * `neighbours='rings'`. Names become values through one table per choice (chooseNamed); an
 * unknown name is a pcl::BadArgumentException listing the names.
 */
#include <pcl/exceptions.h>

#include <initializer_list>
#include <string>
#include <utility>
#include <vector>

namespace pcl_ddg {

struct OptionStyle {
  const char* prefix;     ///< before an option's name: "-" or ""
  const char* equals;     ///< between an option and its value: " " or "="
  const char* quote;      ///< around a value that is a name: "" or "'"
  const char* separator;  ///< between the names of a list, and between settings
  const char* listed;     ///< between the names a choice accepts: "|" or ", "

  std::string option(const std::string& name) const { return prefix + name; }
  /** A value that is a name, as the caller writes it: rings, or 'rings'. */
  std::string name(const std::string& value) const { return quote + value + quote; }
  /** option and value: "-neighbours rings", "neighbours='rings'". */
  std::string setting(const std::string& option_name, const std::string& value) const {
    return option(option_name) + equals + name(value);
  }
  /** option and a placeholder: "-radius r", "radius=r". */
  std::string placeholder(const std::string& option_name, const std::string& value) const {
    return option(option_name) + equals + value;
  }
};

/** The command-line tools and the viewer. */
inline constexpr OptionStyle kToolStyle{"-", " ", "", " ", "|"};
/** The Python module. */
inline constexpr OptionStyle kPythonStyle{"", "=", "'", ", ", ", "};

/** One name a choice accepts and the value it stands for. */
template <typename Value>
struct Named {
  const char* name;
  Value value;
};

/**
 * The value of name among choices (former spellings may follow the listed names: they are
 * accepted, not listed). Throws pcl::BadArgumentException "<option> must be one of a|b|c, not
 * 'x'" in the caller's style.
 */
template <typename Value>
Value chooseNamed(const std::string& option, const std::string& name,
                  std::initializer_list<Named<Value>> choices, const OptionStyle& style,
                  std::size_t listed = static_cast<std::size_t>(-1)) {
  std::string names;
  std::size_t i = 0;
  for (const Named<Value>& c : choices) {
    if (name == c.name) return c.value;
    if (i++ < listed) names += (names.empty() ? "" : style.listed) + style.name(c.name);
  }
  throw pcl::BadArgumentException(style.option(option) + " must be one of " + names + ", not '" +
                                  name + "'");
}

}  // namespace pcl_ddg
