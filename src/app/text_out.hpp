#pragma once
// Formatted text appended to a string: what the identification's reports and methods write instead of printing, so
// that the façade prints nothing and its caller chooses where the text goes.
#include <iterator>
#include <string>
#include <utility>

#include <fmt/format.h>

namespace cnccomp::app {

class TextOut {
public:
    explicit TextOut(std::string& text) : text_(&text) {}
    template <class... Args>
    void operator()(fmt::format_string<Args...> format, Args&&... args) const {
        fmt::format_to(std::back_inserter(*text_), format, std::forward<Args>(args)...);
    }

private:
    std::string* text_;
};

}  // namespace cnccomp::app
