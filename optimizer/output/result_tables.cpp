#include "optimizer/output/result_tables.hpp"

#include <stdexcept>

#include "core/model/rotation.hpp"

namespace beamrail {

bool TimeseriesWriter::open(const std::filesystem::path& path, const Model& model,
                            std::string* error) {
  std::vector<std::string> header{"t"};
  for (int i : model.free_bodies) {
    if (model.bodies[i].generated) continue;
    bodies_.push_back(i);
    reference_.push_back(model.bodies[i].position);
    for (const char* c : {".x", ".y", ".z", ".q0", ".q1", ".q2", ".q3"})
      header.push_back(model.bodies[i].name + c);
  }
  header.push_back("energy");
  flushed_ = std::chrono::steady_clock::now();
  return table_.open(path, header, error, true);
}

void TimeseriesWriter::write(const TransientSample& sample, const Data& data) {
  row_.clear();
  row_.push_back(sample.t);
  for (size_t k = 0; k < bodies_.size(); ++k) {
    const int i = bodies_[k];
    const Vec3 c = reference_[k] + data.pose[i].u;
    const Vec4 q = data.q[i] / data.q[i].norm();
    row_.insert(row_.end(), {c(0), c(1), c(2), q(0), q(1), q(2), q(3)});
  }
  row_.push_back(sample.energy());
  table_.row(row_);
  const auto now = std::chrono::steady_clock::now();
  if (now - flushed_ >= kTimeseriesFlushInterval) {
    table_.flush();
    flushed_ = now;
  }
  if (!table_.good()) throw std::runtime_error(table_.error());
}

bool write_result_tables(const std::filesystem::path& directory,
                         const std::vector<ResultTable>& tables, std::string* error) {
  for (const ResultTable& table : tables) {
    CsvWriter writer;
    if (!writer.open(directory / table.file, table.header, error, true)) return false;
    for (const std::vector<std::string>& row : table.rows) writer.row(row);
    if (!writer.commit(error)) return false;
  }
  return true;
}

bool TimeseriesFiles::begin(const std::string& file, const Model& model, std::string* error) {
  writer_.emplace();
  return writer_->open(directory_ / file, model, error);
}

void TimeseriesFiles::sample(const TransientSample& sample, const Data& data) {
  writer_->write(sample, data);
}

bool TimeseriesFiles::end(std::string* error) {
  const bool ok = writer_->commit(error);
  writer_.reset();
  return ok;
}

}  // namespace beamrail
