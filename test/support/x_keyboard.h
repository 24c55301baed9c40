#pragma once
// Key presses sent through the X server, as a keyboard's arrive, to drive a tool's window.
#include <chrono>
#include <string>
#include <vector>

namespace pcl_ddg {
namespace test {

/** Sends a press and release of each X key sym ("v", "F12", "q") to the first window named
 *  window_name on $DISPLAY, waiting up to wait_for_window for it to appear and take key input;
 *  false if it did not (or there is no display). */
bool sendKeys(const std::string& window_name, const std::vector<std::string>& key_syms,
              std::chrono::milliseconds wait_for_window);

}  // namespace test
}  // namespace pcl_ddg
