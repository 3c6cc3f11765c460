// Copyright wild_mvs authors.
#include "wild_mvs/cli/option_command.h"

#include <filesystem>

namespace wild_mvs {
namespace cli {

OptionCommand::OptionCommand(const CommandSpec& spec, const CommandArgs& argv,
                             ReconstructConfig* config)
    : spec_(spec), config_(config) {
  RegisterOptions(config_, &options_);
  args_.emplace(spec_, argv, &options_);
}

bool OptionCommand::PrintHelpIfAsked(std::ostream& os) const {
  if (!args_->help()) return false;
  PrintCommandHelp(spec_, &options_, os);
  return true;
}

void OptionCommand::ApplyConfigFileAndFlags(OptionSet* set) const {
  if (args_->Has("config")) set->LoadYamlFile(args_->Get("config"));
  args_->ApplyCoreAssignments(set);
}

void OptionCommand::Configure() {
  ApplyConfigFileAndFlags(&options_);
  config_->Check();
}

bool OptionCommand::ConfigureWithRunRecord(const std::string& out,
                                           DatasetRecord* record) {
  OptionSet with_record;
  RegisterOptions(config_, &with_record);
  RegisterDatasetRecord(record, &with_record);
  const bool has_record = std::filesystem::exists(RunRecordPath(out));
  if (has_record) with_record.LoadYamlFile(RunRecordPath(out));
  ApplyConfigFileAndFlags(&with_record);
  config_->Check();
  return has_record;
}

}  // namespace cli
}  // namespace wild_mvs
