#include "core/cli/paper_option.h"

#include "core/base/enum_names.h"
#include "core/training/paper_switches.h"

namespace tod::cli {

void AddPaperOption(CLI::App* cmd, std::vector<std::string>& names) {
  cmd->add_option(
         "--paper", names,
         "train this part as the paper does (repeatable; default: none):" + PaperSwitchesHelp())
      ->check(CLI::IsMember(EnumNameList<PaperSwitch>()))
      ->expected(1)
      ->multi_option_policy(CLI::MultiOptionPolicy::TakeAll);
}

void ApplyPaperSwitches(const std::vector<std::string>& names, TrainOptions& options) {
  for (const std::string& name : names)
    ApplyPaperSwitch(*ParseEnum<PaperSwitch>(name), options);  // checked by CLI11
}

}  // namespace tod::cli
