// SPDX-License-Identifier: GPL-2.0-or-later
#include "ops/discover.hpp"

#include <fstream>

#include "error/error.hpp"
#include "files/atomic_file.hpp"
#include "lbp/bytes.hpp"

namespace i20::ops {
namespace {

// The overlay as every later command will read it: merged into the database as loaded,
// then resolved for the revision it names.
void prove_loads(const params::ParamDb& loaded, const std::string& yaml, const std::string& source,
                 std::uint16_t swrevision) {
  auto probe = loaded;
  probe.apply_overlay_string(yaml, source);
  (void)probe.for_firmware(swrevision);
}

}  // namespace

DiscoverResult discover(Amp& amp, const params::ParamDb& loaded, const DiscoverOptions& options) {
  DiscoverResult result;
  // The file is refused before the reset and the scan: they cost the card's working values
  // and a thousand reads, and a refusal needs neither.
  result.written = options.output.empty()
                       ? std::filesystem::path("i20-map-" + lbp::hex_value(amp.swrevision(), 4) + ".yaml")
                       : options.output;
  const std::string file = result.written.string();
  if (!options.overwrite && std::filesystem::exists(result.written))
    throw UsageError(file + " exists; pass --overwrite to replace it (or choose another name with -o)");
  result.report = device::discover(amp.device(), options.scan);
  const std::string yaml = result.report.overlay_yaml(options.generated_at);
  prove_loads(loaded, yaml, file, result.report.swrevision);
  files::write_file(result.written, yaml,
                    options.overwrite ? files::Existing::Replace : files::Existing::Refuse);
  auto again = loaded;
  again.apply_overlay_file(result.written);
  (void)again.for_firmware(result.report.swrevision);
  return result;
}

}  // namespace i20::ops
