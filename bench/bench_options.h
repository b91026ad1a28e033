// The command-line options of the bench C++ programs (cluster_pairs.cpp, cluster_pairs_2d.cpp,
// cluster_lists.cpp): each option bound to a variable, `--name VALUE` (int and double as
// std::atoi / std::atof read them, or a string) or a `--name` switch that sets a bool.
//
//   bench::Options opts;
//   opts.value("--nx", nx).value("--hdx", hdx).flag("--fill", fill);
//   if (!opts.parse(argc, argv, "[--nx 47] [--hdx 1.5] [--fill]")) return 2;
//
// An unknown option or one without its value prints `usage: PROGRAM SYNOPSIS` on stderr and
// makes parse return false (the programs then exit with 2).
#pragma once

#include <cstdio>
#include <cstdlib>
#include <functional>
#include <string>
#include <utility>
#include <vector>

namespace bench {

class Options {
 public:
  Options& value(const char* name, int& v) {
    return add(name, true, [&v](const char* s) { v = std::atoi(s); });
  }
  Options& value(const char* name, double& v) {
    return add(name, true, [&v](const char* s) { v = std::atof(s); });
  }
  Options& value(const char* name, std::string& v) {
    return add(name, true, [&v](const char* s) { v = s; });
  }
  Options& flag(const char* name, bool& v) {
    return add(name, false, [&v](const char*) { v = true; });
  }

  // Sets the variables of the options argv[1..argc) names, in order; false (after the usage)
  // at an unknown option or a missing value.
  bool parse(int argc, char** argv, const char* synopsis) const {
    for (int k = 1; k < argc; ++k) {
      const Option* o = find(argv[k]);
      if (!o || (o->takesValue && k + 1 >= argc)) {
        std::fprintf(stderr, "usage: %s %s\n", argv[0], synopsis);
        return false;
      }
      o->set(o->takesValue ? argv[++k] : nullptr);
    }
    return true;
  }

 private:
  struct Option {
    std::string name;
    bool takesValue;
    std::function<void(const char*)> set;
  };
  Options& add(const char* name, bool takesValue, std::function<void(const char*)> set) {
    options_.push_back({name, takesValue, std::move(set)});
    return *this;
  }
  const Option* find(const std::string& name) const {
    for (const Option& o : options_)
      if (o.name == name) return &o;
    return nullptr;
  }
  std::vector<Option> options_;
};

}  // namespace bench
