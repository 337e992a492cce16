// SPDX-License-Identifier: GPL-2.0-or-later
#include "console/router.hpp"

#include <fstream>
#include <sstream>

#include "console/static_files.hpp"

namespace i20::console {

Response Router::handle(const Request& request) {
  if (auto refusal = gate_.judge(request)) return std::move(*refusal);
  const auto [path, query] = split_target(text(request.target()));
  if (path.rfind("/api/", 0) == 0) {
    try {
      return api_->handle(request);
    } catch (const std::exception& e) {  // the Api answers its own failures; this is a last resort
      std::string message = "internal error: ";
      message += e.what();
      return error_response(http::status::internal_server_error, message, request);
    }
  }
  if (request.method() != http::verb::get)
    return error_response(http::status::method_not_allowed, "pages are read with GET", request);
  return serve_static(request, path);
}

std::optional<Response> Router::admit_upgrade(const Request& request) const {
  if (auto refusal = gate_.judge_upgrade(request)) return refusal;
  if (split_target(text(request.target())).first != kLivePath)
    return error_response(http::status::not_found, "the only WebSocket is /api/live", request);
  return std::nullopt;
}

Response Router::serve_static(const Request& request, const std::string& path) const {
  StaticFile file;
  switch (find_static(static_dir_, path, file)) {
    case StaticLookup::Forbidden:
      return error_response(http::status::bad_request,
                            "refused: the path leaves the console's folder or names "
                            "a file type it does not serve",
                            request);
    case StaticLookup::NotFound: return error_response(http::status::not_found, "no such page", request);
    case StaticLookup::Found: break;
  }
  std::ifstream in(file.path, std::ios::binary);
  std::ostringstream body;
  body << in.rdbuf();
  if (!in) return error_response(http::status::internal_server_error, "the page could not be read", request);
  return make_response(http::status::ok, body.str(), file.content_type, request);
}

}  // namespace i20::console
