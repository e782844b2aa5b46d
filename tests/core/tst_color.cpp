// Colour: the CIE table loader, blackbody chromaticities on the Planckian locus, XYZ -> sRGB, sun colours.
#include <QTest>

#include <cmath>
#include <limits>
#include <string>

#include "core/base/error.h"
#include "core/color/color.h"
#include "core/render/tonemap.h"

using namespace sylva;

namespace {

const std::string kCiePath = std::string(SYLVA_RESOURCES) + "/color/cie1931_2deg_xyz_cmf_360-830_1nm.csv";

} // namespace

class TestColor : public QObject {
    Q_OBJECT
private:
    CieTable m_cie;

private Q_SLOTS:
    void initTestCase() { m_cie = loadCieCsv(kCiePath); }

    void tableShape()
    {
        QCOMPARE(m_cie.lambda0, 360.0);
        QCOMPARE(m_cie.step, 1.0);
        QCOMPARE(m_cie.xyzBar.size(), size_t(471));   // 360..830 nm
        // ybar is the photopic luminous efficiency: 1 at 555 nm.
        QVERIFY(std::fabs(m_cie.xyzBar[555 - 360].y - 1.0) < 1e-6);
    }

    // Expected xy of Planckian radiators with the CIE 1931 2-degree observer (1 nm table, 360-830 nm).
    // Every value was also recomputed independently for this test: a plain-Python rectangle-rule
    // integration of Planck's law (exact SI h, c, k_B) against resources/color/cie1931_...csv, which
    // agrees with the expected values below to <= 3e-5.
    void planckianLocus_data()
    {
        QTest::addColumn<double>("kelvin");
        QTest::addColumn<double>("x");
        QTest::addColumn<double>("y");
        // CIE 15:2004 Table T.1, Illuminant A (0.44757, 0.40745): its SPD is Planck with c2 = 1.435e-2 m K at
        // 2848 K, the same curve as 2856 K with today's c2 = 1.4388e-2 m K. Python: (0.44754, 0.40743).
        QTest::newRow("2856 K = Illuminant A") << 2856.0 << 0.44757 << 0.40745;
        // Commonly quoted Planckian-locus points (4 decimals, as given in the colour task's brief), each
        // confirmed by the Python integration: 3000 K (0.43693, 0.40407), 5000 K (0.34510, 0.35161),
        // 6500 K (0.31353, 0.32363), 10000 K (0.28063, 0.28829).
        QTest::newRow("3000 K") << 3000.0 << 0.4369 << 0.4041;
        QTest::newRow("5000 K") << 5000.0 << 0.3451 << 0.3516;
        QTest::newRow("6500 K") << 6500.0 << 0.3135 << 0.3237;
        QTest::newRow("10000 K") << 10000.0 << 0.2807 << 0.2884;
        // The ends of the accepted range; values from the independent Python integration only.
        QTest::newRow("1000 K (python)") << 1000.0 << 0.65275 << 0.34446;
        QTest::newRow("40000 K (python)") << 40000.0 << 0.24720 << 0.24472;
    }

    void planckianLocus()
    {
        QFETCH(double, kelvin);
        QFETCH(double, x);
        QFETCH(double, y);
        const glm::dvec2 xy = chromaticity(blackbodyXyz(kelvin, m_cie));
        QVERIFY2(std::fabs(xy.x - x) < 5e-4 && std::fabs(xy.y - y) < 5e-4,
                 qPrintable(QString("T = %1 K: xy = (%2, %3), expected (%4, %5)")
                                .arg(kelvin).arg(xy.x, 0, 'f', 5).arg(xy.y, 0, 'f', 5).arg(x).arg(y)));
    }

    void blackbodyScalesWithTemperature()
    {
        // Total radiance grows like T^4, so the visible part grows strongly and monotonically with T.
        double previous = 0.0;
        for (double t = 1000.0; t <= 40000.0; t *= 1.25) {
            const glm::dvec3 xyz = blackbodyXyz(t, m_cie);
            QVERIFY(xyz.x > 0.0 && xyz.y > 0.0 && xyz.z > 0.0);
            QVERIFY(xyz.y > previous);
            previous = xyz.y;
        }
    }

    void chromaticityOfZeroIsZero()
    {
        QCOMPARE(chromaticity(glm::dvec3(0.0)), glm::dvec2(0.0));
        const glm::dvec2 xy = chromaticity(glm::dvec3(1.0, 2.0, 1.0));
        QVERIFY(std::fabs(xy.x - 0.25) < 1e-15 && std::fabs(xy.y - 0.5) < 1e-15);
    }

    void d65WhiteMapsToSrgbWhite()
    {
        // D65 white point, XYZ with Y = 1 (CIE 15:2004: x = 0.31272, y = 0.32903).
        const double x = 0.31272, y = 0.32903;
        const glm::dvec3 rgb = xyzToLinearSrgb(glm::dvec3(x / y, 1.0, (1.0 - x - y) / y));
        for (int c = 0; c < 3; ++c) QVERIFY2(std::fabs(rgb[c] - 1.0) < 1e-3, qPrintable(QString::number(rgb[c])));
        // The middle row of the inverse matrix is the Rec. 709 luminance: Y of an sRGB colour is kept.
        const glm::dvec3 someXyz(0.3, 0.4, 0.2);
        const glm::dvec3 someRgb = xyzToLinearSrgb(someXyz);
        QVERIFY(std::fabs(0.2126 * someRgb.x + 0.7152 * someRgb.y + 0.0722 * someRgb.z - someXyz.y) < 1e-3);
    }

    void sunColorNearWhiteAt6500()
    {
        const glm::vec3 c = sunColor(6500.0, m_cie);
        for (int i = 0; i < 3; ++i) QVERIFY2(std::fabs(c[i] - 1.0f) < 0.05f, qPrintable(QString("channel %1 = %2").arg(i).arg(c[i])));
    }

    void sunColorReddishAt3000()
    {
        const glm::vec3 c = sunColor(3000.0, m_cie);
        QVERIFY2(c.x > c.y && c.y > c.z && c.z > 0.0f, qPrintable(QString("%1 %2 %3").arg(c.x).arg(c.y).arg(c.z)));
        const glm::vec3 hot = sunColor(20000.0, m_cie);
        QVERIFY(hot.z > hot.y && hot.y > hot.x);   // bluish
    }

    void sunColorHasUnitLuminanceAndNoNegatives()
    {
        // 1000 K lies outside the sRGB gamut (negative blue before clamping): still luminance 1.
        for (double t : {1000.0, 1500.0, 2000.0, 3000.0, 4500.0, 5778.0, 6500.0, 10000.0, 25000.0, 40000.0}) {
            const glm::vec3 c = sunColor(t, m_cie);
            QVERIFY(c.x >= 0.0f && c.y >= 0.0f && c.z >= 0.0f);
            QVERIFY2(std::fabs(luminance(c) - 1.0f) < 1e-5f, qPrintable(QString("T = %1: Y = %2").arg(t).arg(luminance(c))));
        }
        QCOMPARE(sunColor(1000.0, m_cie).z, 0.0f);
    }

    void badKelvinThrows_data()
    {
        QTest::addColumn<double>("kelvin");
        QTest::addColumn<QString>("bound");
        QTest::newRow("below") << 999.0 << "minimum 1000";
        QTest::newRow("zero") << 0.0 << "minimum 1000";
        QTest::newRow("negative") << -6500.0 << "minimum 1000";
        QTest::newRow("above") << 40001.0 << "maximum 40000";
        QTest::newRow("nan") << std::numeric_limits<double>::quiet_NaN() << "[1000, 40000]";
        QTest::newRow("inf") << std::numeric_limits<double>::infinity() << "[1000, 40000]";
    }

    void badKelvinThrows()
    {
        QFETCH(double, kelvin);
        QFETCH(QString, bound);
        for (int which = 0; which < 2; ++which) {
            try {
                if (which == 0) blackbodyXyz(kelvin, m_cie);
                else sunColor(kelvin, m_cie);
                QFAIL("no Error thrown");
            } catch (const Error& e) {
                QVERIFY2(QString(e.what()).contains(bound), e.what());
            }
        }
    }

    void parsesCommentsHeaderAndCrlf()
    {
        const CieTable t = parseCieCsv("# comment\r\nlambda_nm,xbar,ybar,zbar\r\n\r\n400, 0.1,0.2,0.3\r\n405,0.4,0.5,0.6\r\n410,1e-3,0,0");
        QCOMPARE(t.lambda0, 400.0);
        QCOMPARE(t.step, 5.0);
        QCOMPARE(t.xyzBar.size(), size_t(3));
        QCOMPARE(t.xyzBar[1], glm::dvec3(0.4, 0.5, 0.6));
        QCOMPARE(t.xyzBar[2], glm::dvec3(1e-3, 0.0, 0.0));
    }

    void malformedCsvThrows_data()
    {
        QTest::addColumn<QString>("text");
        QTest::addColumn<QString>("message");
        QTest::newRow("empty") << "" << "at least 2";
        QTest::newRow("header only") << "lambda_nm,xbar,ybar,zbar\n" << "at least 2";
        QTest::newRow("one row") << "400,0,0,0\n" << "at least 2";
        QTest::newRow("three fields") << "400,0,0,0\n401,0,0\n" << "line 2: expected 4";
        QTest::newRow("five fields") << "400,0,0,0,0\n401,0,0,0\n" << "found 5";
        QTest::newRow("not a number") << "400,0,0,0\n401,0,x,0\n" << "ybar 'x' is not a number";
        QTest::newRow("trailing junk") << "400,0,0,0\n401,0.5abc,0,0\n" << "xbar '0.5abc'";
        QTest::newRow("empty field") << "400,0,0,0\n401,,0,0\n" << "not a number";
        QTest::newRow("nan") << "400,0,0,0\n401,0,0,nan\n" << "not finite";
        QTest::newRow("negative cmf") << "400,0,0,0\n401,0,-0.5,0\n" << ">= 0";
        QTest::newRow("decreasing") << "400,0,0,0\n399,0,0,0\n" << "does not increase";
        QTest::newRow("repeated") << "400,0,0,0\n400,0,0,0\n" << "does not increase";
        QTest::newRow("uneven") << "400,0,0,0\n401,0,0,0\n403,0,0,0\n" << "uniform spacing";
        QTest::newRow("zero wavelength") << "0,0,0,0\n1,0,0,0\n" << "must be > 0";
        QTest::newRow("text after data") << "400,0,0,0\n401,0,0,0\nfoo\n" << "line 3: unexpected text";
        QTest::newRow("two headers") << "a,b,c,d\na,b,c,d\n400,0,0,0\n" << "unexpected text";
    }

    void malformedCsvThrows()
    {
        QFETCH(QString, text);
        QFETCH(QString, message);
        const std::string utf8 = text.toStdString();
        try {
            parseCieCsv(utf8);
            QFAIL("no Error thrown");
        } catch (const Error& e) {
            QVERIFY2(QString(e.what()).contains(message), e.what());
        }
    }

    void loadErrorsNameTheFile()
    {
        const std::string missing = std::string(SYLVA_TEST_OUTPUT) + "/no_such_cie_table.csv";
        try {
            loadCieCsv(missing);
            QFAIL("no Error thrown");
        } catch (const Error& e) {
            QVERIFY2(QString(e.what()).contains(QString::fromStdString(missing)), e.what());
        }
        // A file that is not a CMF table: the message names the file and the line.
        const std::string license = std::string(SYLVA_RESOURCES) + "/color/LICENSE.colour.BSD3.txt";
        try {
            loadCieCsv(license);
            QFAIL("no Error thrown");
        } catch (const Error& e) {
            QVERIFY2(QString(e.what()).contains(QString::fromStdString(license)) && QString(e.what()).contains("line"), e.what());
        }
    }

    void emptyTableThrows()
    {
        QVERIFY_THROWS_EXCEPTION(Error, blackbodyXyz(5000.0, CieTable{}));
    }
};

QTEST_APPLESS_MAIN(TestColor)
#include "tst_color.moc"
