#include "plugins/fold_sequence/fold_sequence_plugin.h"

CREASE_PLUGIN(crease::fold::FoldSequencePlugin, "fold_sequence", "1.0.0")
