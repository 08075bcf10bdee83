// Placeholder: the plot renderer (issue 7) is being written.
#pragma once
