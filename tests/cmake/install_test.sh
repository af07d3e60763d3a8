#!/usr/bin/env bash
# Installs the build into a staging root (DESTDIR), checks the tree, builds the out-of-tree
# example against the installed SDK and runs it and the simulated robot in the installed
# daemon; then builds the Debian package with cpack and checks what dpkg-deb says of it.
# Usage: install_test.sh BUILD_DIR SOURCE_DIR
set -euo pipefail
build=$(realpath "$1")
src=$(realpath "$2")
work=$(mktemp -d /tmp/crease-install-test.XXXXXX)
trap 'rm -rf "$work"' EXIT
chmod 755 "$work"
umask 002   # the install must not inherit a group-writable umask
fail() { echo "FAIL: $*" >&2; exit 1; }
step() { echo "--- $*"; }

prefix=/opt/crease
stage=$work/stage
root=$stage$prefix

step "cmake --install into $stage$prefix"
DESTDIR=$stage cmake --install "$build" --prefix "$prefix" > "$work/install.log" || { cat "$work/install.log"; fail "install"; }

step "layout"
for f in bin/creased bin/creasectl lib/libcrease_core.so lib/libcrease_rt.so lib/libcrease_frames.so \
         lib/crease/plugins/libhand_driver.so lib/crease/plugins/libsheet_model.so \
         share/crease/config/sim.yaml share/crease/config/robot/crease_robot.urdf \
         include/crease/core/plugin.h include/crease/core/port_types/hand.h \
         lib/cmake/Crease/CreaseConfig.cmake lib/cmake/Crease/CreaseConfigVersion.cmake \
         share/doc/crease/README.md; do
  [ -e "$root/$f" ] || fail "$prefix/$f not installed"
done
[ -f "$stage/etc/crease/robot.yaml" ] || fail "/etc/crease/robot.yaml not installed"
[ -f "$stage/etc/crease/cameras/cam0.yaml" ] || fail "/etc/crease/cameras not installed"
[ -f "$stage/lib/systemd/system/creased.service" ] || fail "creased.service not installed"
[ ! -e "$root/lib/crease/plugins/libcrease_test_thrower.so" ] || fail "a test-only plugin was installed"
writable=$(find "$stage" -perm /022 ! -type l)
[ -z "$writable" ] || fail "writable by group or others: $writable"
grep -q "plugin_dirs: \[$prefix/lib/crease/plugins\]" "$stage/etc/crease/robot.yaml" \
  || fail "/etc/crease/robot.yaml does not name the installed plugin directory"
grep -q "plugin_dirs: \[../../../lib/crease/plugins\]" "$root/share/crease/config/sim.yaml" \
  || fail "sim.yaml does not name the installed plugin directory"
for y in control vision; do
  grep -q "plugin_dirs: \[../../../../lib/crease/plugins\]" "$root/share/crease/config/split/$y.yaml" \
    || fail "split/$y.yaml does not name the installed plugin directory"
done
grep -q "ExecStart=$prefix/bin/creased" "$stage/lib/systemd/system/creased.service" || fail "unit's ExecStart"
if grep -rl -e "$src" -e "build/release" "$root/share/crease/config" "$stage/etc/crease"; then
  fail "an installed configuration refers to the source or build tree"
fi
runpath=$(readelf -d "$root/bin/creased" | grep -E 'RUNPATH|RPATH' || true)
[[ "$runpath" == *'$ORIGIN/../lib'* && "$runpath" != *"$build"* ]] || fail "creased's run path: $runpath"

step "every SDK header compiles on its own against the installed include folder"
(cd "$root/include/crease" && find . -name '*.h' | sort) > "$work/headers"
while read -r h; do
  echo "#include \"${h#./}\"" | g++ -std=c++20 -Wall -Wextra -Werror -fsyntax-only -I"$root/include/crease" -x c++ - \
    || fail "SDK header ${h#./} does not compile alone"
done < "$work/headers"
! grep -q "daemon/\|config/\|control/\|report/\|plugin_host\|plugin_library" "$work/headers" \
  || fail "the SDK exposes the host's internals: $(cat "$work/headers")"

step "the out-of-tree example against the installed SDK"
cmake -S "$src/examples/out_of_tree_plugin" -B "$work/example" -G Ninja -DCMAKE_PREFIX_PATH="$root" \
  > "$work/example-configure.log" || { cat "$work/example-configure.log"; fail "example configure"; }
cmake --build "$work/example" > "$work/example-build.log" || { cat "$work/example-build.log"; fail "example build"; }
[ -f "$work/example/libexample_doubler.so" ] || fail "the example's plugin was not built"
chmod -R go-w "$work/example"

step "an SDK of another ABI major version is refused at find_package"
mkdir -p "$work/other_abi"
cat > "$work/other_abi/CMakeLists.txt" <<'CM'
cmake_minimum_required(VERSION 3.25)
project(other_abi LANGUAGES CXX)
find_package(Crease 1 REQUIRED)
CM
if cmake -S "$work/other_abi" -B "$work/other_abi/build" -DCMAKE_PREFIX_PATH="$root" > "$work/other.log" 2>&1; then
  fail "find_package(Crease 1) accepted an SDK of ABI $(grep -o 'PACKAGE_VERSION "[^"]*"' "$root/lib/cmake/Crease/CreaseConfigVersion.cmake")"
fi
grep -q "considered but not accepted" "$work/other.log" || { cat "$work/other.log"; fail "no version message"; }

step "the example's plugins run in the installed daemon"
sed "s|plugin_dirs: \[build\]|plugin_dirs: [$root/lib/crease/plugins, $work/example]|" \
  "$src/examples/out_of_tree_plugin/doubler.yaml" > "$work/doubler.yaml"
"$root/bin/creased" --config "$work/doubler.yaml" --duration 1 --no-progress --socket "$work/doubler.sock" \
  > "$work/doubler.out" 2>&1 || { cat "$work/doubler.out"; fail "creased with the example exited non-zero"; }
grep -q "example gain.*42" "$work/doubler.out" || { cat "$work/doubler.out"; fail "the doubled gain (42) is not in the summary"; }

step "the simulated robot runs from the installed tree"
"$root/bin/creased" --config "$root/share/crease/config/sim.yaml" --duration 4 --no-progress \
  --socket "$work/sim.sock" --report-dir "$work/reports" > "$work/sim.out" 2>&1 \
  || { tail -40 "$work/sim.out"; fail "creased with the installed sim.yaml exited non-zero"; }
[ -f "$work/reports/report.json" ] || fail "no report from the installed simulated robot"

step "systemd accepts the installed unit"
command -v systemd-analyze > /dev/null || fail "systemd-analyze missing (tools/setup installs systemd)"
{
  # verify resolves ExecStart: point it at the staged binary.
  sed "s|$prefix/bin/creased|$root/bin/creased|" "$stage/lib/systemd/system/creased.service" > "$work/creased.service"
  systemd-analyze verify "$work/creased.service" > "$work/verify.log" 2>&1 || { cat "$work/verify.log"; fail "systemd-analyze verify"; }
  ! grep -q "creased.service" "$work/verify.log" || { cat "$work/verify.log"; fail "systemd-analyze verify warns"; }
}

step "cpack -G DEB"
(cd "$work" && cpack --config "$build/CPackConfig.cmake" -G DEB -B "$work/pkg" > "$work/cpack.log" 2>&1) \
  || { cat "$work/cpack.log"; fail "cpack"; }
deb=$(ls "$work"/pkg/crease_*_amd64.deb 2>/dev/null | head -1)
[ -n "$deb" ] || { cat "$work/cpack.log"; fail "no crease_<version>_amd64.deb"; }
dpkg-deb --info "$deb" > "$work/info"
dpkg-deb --contents "$deb" > "$work/contents"
grep -q "Package: crease" "$work/info" || fail "package name"
for dep in adduser libc6 libopencv libyaml-cpp libode libddsc; do
  grep "Depends:" "$work/info" | grep -q "$dep" || { grep "Depends:" "$work/info"; fail "Depends lacks $dep"; }
done
if grep "Depends:" "$work/info" | grep -q -- "-dev"; then grep "Depends:" "$work/info"; fail "a build-only (-dev) dependency"; fi
grep -q "postinst" "$work/info" && grep -q "conffiles" "$work/info" || { cat "$work/info"; fail "postinst or conffiles missing"; }
dpkg-deb --ctrl-tarfile "$deb" | tar -xO ./conffiles > "$work/conffiles"
grep -qx "/etc/crease/robot.yaml" "$work/conffiles" || fail "/etc/crease/robot.yaml is not a conffile"
dpkg-deb --ctrl-tarfile "$deb" | tar -xO ./postinst | grep -q "adduser --system" || fail "postinst does not create the crease user"
grep -q " ./lib/systemd/system/creased.service$" "$work/contents" || fail "the unit is not in the package"
grep -E "^drwxr-xr-x .* ./opt/crease/lib/crease/plugins/$" "$work/contents" > /dev/null \
  || { grep "plugins/$" "$work/contents"; fail "the plugins' directory is not 0755"; }
! grep -q "etc/systemd/system/multi-user.target.wants" "$work/contents" || fail "the unit is enabled by the package"
echo "OK: $(basename "$deb"), $(grep -c . "$work/contents") entries"
