// The timing charts' SVG: bar widths proportional to the values, texts escaped.

#include <gtest/gtest.h>

#include <regex>
#include <string>
#include <vector>

#include "featsense/viewer_export/html_text.hpp"
#include "featsense/viewer_export/svg_bar_chart.hpp"

namespace featsense::viewer_export {
namespace {

std::vector<double> bar_widths(const std::string& svg) {
  std::vector<double> widths;
  const std::regex bar("<rect class=\"bar\"[^>]* width=\"([0-9.]+)\"");
  for (auto it = std::sregex_iterator(svg.begin(), svg.end(), bar); it != std::sregex_iterator();
       ++it)
    widths.push_back(std::stod((*it)[1]));
  return widths;
}

TEST(SvgBarChart, BarsAreProportionalToTheirValues) {
  BarChart chart;
  chart.title = "stages";
  chart.unit = "ms";
  chart.bars = {{"read", 10.0}, {"integrate", 40.0}, {"flush", 0.0}, {"shift", 20.0}};
  const std::string svg = svg_bar_chart(chart);
  const std::vector<double> widths = bar_widths(svg);
  ASSERT_EQ(widths.size(), 4u) << svg;
  ASSERT_GT(widths[1], 100.0);  // the largest spans the plot
  EXPECT_NEAR(widths[0] / widths[1], 0.25, 0.002);
  EXPECT_EQ(widths[2], 0.0);
  EXPECT_NEAR(widths[3] / widths[1], 0.5, 0.002);
  EXPECT_NE(svg.find(">40 ms<"), std::string::npos) << svg;
  EXPECT_EQ(svg.rfind("<svg", 0), 0u);
  EXPECT_EQ(svg.find("http"), std::string::npos);  // inline: no namespace address either
}

TEST(SvgBarChart, EscapesLabelsTitleAndUnit) {
  BarChart chart;
  chart.title = "<script>alert(1)</script>";
  chart.unit = "\"&'";
  chart.bars = {{"a<b>", 1.0}};
  const std::string svg = svg_bar_chart(chart);
  EXPECT_EQ(svg.find("<script"), std::string::npos) << svg;
  EXPECT_EQ(svg.find("<b>"), std::string::npos) << svg;
  EXPECT_NE(svg.find("&lt;script&gt;alert(1)&lt;/script&gt;"), std::string::npos) << svg;
  EXPECT_NE(svg.find("a&lt;b&gt;"), std::string::npos) << svg;
  EXPECT_NE(svg.find("1 &quot;&amp;&#39;"), std::string::npos) << svg;
}

TEST(SvgBarChart, AllZeroOrNoBarsDrawNothingWide) {
  BarChart chart;
  chart.bars = {{"a", 0.0}, {"b", -3.0}};
  for (const double w : bar_widths(svg_bar_chart(chart))) EXPECT_EQ(w, 0.0);
  chart.bars.clear();
  EXPECT_TRUE(bar_widths(svg_bar_chart(chart)).empty());
}

TEST(HtmlText, EscapesTheFiveSpecialCharacters) {
  EXPECT_EQ(html_escape("a&b<c>d\"e'f"), "a&amp;b&lt;c&gt;d&quot;e&#39;f");
  EXPECT_EQ(html_escape("plain"), "plain");
  EXPECT_EQ(number_text(0.000123456), "0.0001235");
  EXPECT_EQ(number_text(-0.0), "0");
}

}  // namespace
}  // namespace featsense::viewer_export
