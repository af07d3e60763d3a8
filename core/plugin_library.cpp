#include "core/plugin_library.h"

#include <dlfcn.h>
#include <sys/stat.h>

#include "core/errors.h"

namespace fs = std::filesystem;

namespace crease {
namespace {

[[noreturn]] void refuse(const fs::path& p, const std::string& why) {
  throw LoadError("plugin library '" + p.string() + "' refused: " + why);
}

// True when `mode` lets group or others write.
bool shared_writable(mode_t mode) { return (mode & (S_IWGRP | S_IWOTH)) != 0; }

bool inside(const fs::path& file, const fs::path& dir) {
  auto f = file.begin();
  for (auto d = dir.begin(); d != dir.end(); ++d, ++f) {
    if (f == file.end() || *f != *d) return false;
  }
  return true;
}

}  // namespace

std::vector<fs::path> canonical_plugin_dirs(const std::vector<fs::path>& dirs) {
  std::vector<fs::path> out;
  for (const fs::path& d : dirs) {
    std::error_code ec;
    const fs::path c = fs::canonical(d, ec);
    if (ec || !fs::is_directory(c)) throw LoadError("plugin directory '" + d.string() + "' refused: it does not exist");
    struct stat st {};
    if (::stat(c.c_str(), &st) != 0) throw LoadError("plugin directory '" + d.string() + "' refused: cannot stat it");
    if (shared_writable(st.st_mode)) {
      throw LoadError("plugin directory '" + c.string() + "' refused: it is writable by group or others (chmod go-w)");
    }
    out.push_back(c);
  }
  return out;
}

std::shared_ptr<PluginLibrary> PluginLibrary::open(const std::string& library, const std::vector<fs::path>& plugin_dirs) {
  if (plugin_dirs.empty()) refuse(library, "no plugin directories are configured");
  const std::vector<fs::path> dirs = canonical_plugin_dirs(plugin_dirs);

  fs::path candidate;
  if (library.find('/') != std::string::npos) {
    candidate = fs::path(library);
  } else {
    for (const fs::path& d : dirs) {
      for (const std::string& file : {"lib" + library + ".so", library + ".so", library}) {
        if (fs::exists(d / file)) {
          candidate = d / file;
          break;
        }
      }
      if (!candidate.empty()) break;
    }
    if (candidate.empty()) refuse(library, "not found as lib" + library + ".so in the plugin directories");
  }

  std::error_code ec;
  const fs::path real = fs::canonical(candidate, ec);
  if (ec) refuse(candidate, "it does not exist");
  bool allowed = false;
  for (const fs::path& d : dirs) allowed = allowed || inside(real, d);
  if (!allowed) refuse(real, "it is outside the configured plugin directories");

  struct stat st {};
  if (::stat(real.c_str(), &st) != 0 || !S_ISREG(st.st_mode)) refuse(real, "it is not a regular file");
  if (shared_writable(st.st_mode)) refuse(real, "it is writable by group or others (chmod go-w)");
  struct stat dst {};
  if (::stat(real.parent_path().c_str(), &dst) != 0 || shared_writable(dst.st_mode)) {
    refuse(real, "its directory is writable by group or others (chmod go-w)");
  }

  std::shared_ptr<PluginLibrary> lib(new PluginLibrary());
  lib->path_ = real;
  lib->handle_ = ::dlopen(real.c_str(), RTLD_NOW | RTLD_LOCAL);
  if (lib->handle_ == nullptr) {
    const char* e = ::dlerror();
    refuse(real, std::string("dlopen failed: ") + (e ? e : "unknown error"));
  }
  ::dlerror();
  void* sym = ::dlsym(lib->handle_, CREASE_PLUGIN_ENTRY_SYMBOL);
  if (sym == nullptr) refuse(real, "it has no entry point '" CREASE_PLUGIN_ENTRY_SYMBOL "' (is CREASE_PLUGIN(...) missing?)");
  auto entry = reinterpret_cast<crease_plugin_entry_fn>(sym);
  const crease_plugin_descriptor* d = entry();
  if (d == nullptr) refuse(real, "its entry point returned no descriptor");
  if (d->abi_version != CREASE_PLUGIN_ABI_VERSION) {
    refuse(real, "it was built for plugin ABI " + std::to_string(d->abi_version) + ", this host speaks ABI " +
                     std::to_string(CREASE_PLUGIN_ABI_VERSION) + " (rebuild the plugin)");
  }
  if (d->struct_size < sizeof(crease_plugin_descriptor)) {
    refuse(real, "its descriptor is " + std::to_string(d->struct_size) + " bytes, the host expects " +
                     std::to_string(sizeof(crease_plugin_descriptor)) + " (rebuild the plugin)");
  }
  if (!d->create || !d->destroy || !d->configure || !d->activate || !d->update || !d->deactivate || !d->cleanup ||
      !d->save_state || !d->load_state || !d->validate_param) {
    refuse(real, "its descriptor lacks a required function");
  }
  lib->descriptor_ = d;
  lib->name_ = d->name ? d->name : "";
  lib->version_ = d->version ? d->version : "";
  return lib;
}

PluginLibrary::~PluginLibrary() {
  if (handle_ != nullptr) ::dlclose(handle_);
}

}  // namespace crease
