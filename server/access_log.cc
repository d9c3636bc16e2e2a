#include "server/access_log.h"

#include "server/logging.h"

namespace tod::server {

nlohmann::json AccessLogFields(const AccessRecord& record) {
  nlohmann::json fields = {{"id", record.id},       {"protocol", record.protocol},
                           {"frame", record.frame}, {"peer", record.peer},
                           {"bytes", record.bytes}, {"status", record.status},
                           {"ms", record.ms}};
  if (record.path) fields["path"] = *record.path;
  if (record.error) fields["error"] = *record.error;
  if (record.cancelled != nullptr) fields["cancelled"] = record.cancelled;
  return fields;
}

void LogAccess(const AccessRecord& record, ServerMetrics& metrics) {
  metrics.RecordRequest(record.protocol, record.code, record.ms / 1000.0);
  LogEvent(record.error ? spdlog::level::warn : spdlog::level::info, record.event,
           AccessLogFields(record));
}

}  // namespace tod::server
