#include "x_keyboard.h"

#include <X11/Xlib.h>

#include <thread>

namespace pcl_ddg {
namespace test {
namespace {

// The first window named `name` at or under `window`, or 0.
Window findWindow(Display* display, Window window, const std::string& name) {
  char* window_name = nullptr;
  if (XFetchName(display, window, &window_name) != 0 && window_name != nullptr) {
    const bool found = name == window_name;
    XFree(window_name);
    if (found) return window;
  }
  Window root = 0, parent = 0, *children = nullptr;
  unsigned int count = 0;
  if (XQueryTree(display, window, &root, &parent, &children, &count) == 0) return 0;
  Window found = 0;
  for (unsigned int i = 0; i < count && found == 0; ++i)
    found = findWindow(display, children[i], name);
  if (children != nullptr) XFree(children);
  return found;
}

void sendKey(Display* display, Window window, const std::string& key_sym) {
  XKeyEvent event{};
  event.display = display;
  event.window = window;
  event.root = DefaultRootWindow(display);
  event.same_screen = True;
  event.keycode = XKeysymToKeycode(display, XStringToKeysym(key_sym.c_str()));
  event.type = KeyPress;
  XSendEvent(display, window, True, KeyPressMask, reinterpret_cast<XEvent*>(&event));
  event.type = KeyRelease;
  XSendEvent(display, window, True, KeyReleaseMask, reinterpret_cast<XEvent*>(&event));
  XFlush(display);
}

}  // namespace

bool sendKeys(const std::string& window_name, const std::vector<std::string>& key_syms,
              std::chrono::milliseconds wait_for_window) {
  Display* display = XOpenDisplay(nullptr);
  if (display == nullptr) return false;
  const auto deadline = std::chrono::steady_clock::now() + wait_for_window;
  // The window must exist and someone must listen to its keys: an event sent before the viewer
  // selects key input is dropped by the server.
  const auto listening = [&](Window window) {
    XWindowAttributes attributes{};
    return window != 0 && XGetWindowAttributes(display, window, &attributes) != 0 &&
           (attributes.all_event_masks & KeyPressMask) != 0;
  };
  Window window = 0;
  while (!listening(window = findWindow(display, DefaultRootWindow(display), window_name)) &&
         std::chrono::steady_clock::now() < deadline) {
    std::this_thread::sleep_for(std::chrono::milliseconds(100));
  }
  if (!listening(window)) window = 0;
  for (const std::string& key_sym : key_syms) {
    if (window != 0) sendKey(display, window, key_sym);
  }
  XCloseDisplay(display);
  return window != 0;
}

}  // namespace test
}  // namespace pcl_ddg
