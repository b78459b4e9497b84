/* SW_ABI_LAYOUT evaluated by the C compiler, for header_cxx.cpp to compare against. */
#include "abi_layout.h"

#define SW_ABI_VALUE(expr) (size_t)(expr),

static const size_t sw_abi_layout_c[] = {SW_ABI_LAYOUT(SW_ABI_VALUE)};

size_t sw_abi_layout_count_c(void) {
    return sizeof sw_abi_layout_c / sizeof sw_abi_layout_c[0];
}

size_t sw_abi_layout_value_c(size_t i) {
    return i < sw_abi_layout_count_c() ? sw_abi_layout_c[i] : (size_t)-1;
}
