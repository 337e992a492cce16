#include "errors.hpp"

#include <yaml-cpp/exceptions.h>

#include <iostream>

#include "device/errors.hpp"
#include "link/link.hpp"
#include "params/param_db.hpp"
#include "params/value.hpp"

namespace i20::app {
namespace {

int print(const char* program, const std::string& kind, const std::string& message, int code) {
  std::cerr << program << ": " << kind << ": " << message << "\n";
  return code;
}

}  // namespace

int report_current_exception(const char* program) {
  try {
    throw;
  } catch (const device::Cancelled& e) {
    return print(program, "interrupted", e.what(), kInterrupted);
  } catch (const device::SafetyError& e) {
    return print(program, "refused", e.what(), kRefused);
  } catch (const device::VerifyError& e) {
    return print(program, "verify failed", e.what(), kCardState);
  } catch (const device::CardStateError& e) {
    return print(program, "card state", e.what(), kCardState);
  } catch (const params::ParamFileError& e) {
    return print(program, "error", e.what(), kBadInput);
  } catch (const params::UnknownParameter& e) {
    return print(program, "error", e.what(), kBadInput);
  } catch (const params::ValueError& e) {
    return print(program, "error", std::string(e.what()) + "; nothing was written", kBadInput);
  } catch (const UsageError& e) {
    return print(program, "error", e.what(), kBadInput);
  } catch (const link::LinkError& e) {
    return print(program, "error", e.what(), kFailure);
  } catch (const Error& e) {
    return print(program, "error", e.what(), kFailure);
  } catch (const YAML::Exception& e) {
    return print(program, "error", std::string("YAML: ") + e.what(), kBadInput);
  } catch (const std::exception& e) {
    return print(program, "error", e.what(), kFailure);
  }
}

}  // namespace i20::app
