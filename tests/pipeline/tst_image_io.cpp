// Image files through OpenImageIO: palette PNGs keep their transparency, grey and 16-bit data, atomic writes, errors.
#include <QColor>
#include <QDir>
#include <QImage>
#include <QTest>

#include "core/base/error.h"
#include "pipeline/io/image_io.h"
#include "tests/common/files.h"

using namespace sylva;

class TestImageIo : public QObject {
    Q_OBJECT

    QString m_dir;

private Q_SLOTS:
    void initTestCase()
    {
        m_dir = test::outputDir("image_io", false);
    }

    void palettePngKeepsTransparency()
    {
        // An 8-bit palette PNG (PLTE + tRNS), written by Qt: index 0 transparent, 1 opaque green, 2 half-transparent red.
        QImage img(4, 2, QImage::Format_Indexed8);
        img.setColorTable({qRgba(0, 0, 0, 0), qRgba(0, 200, 0, 255), qRgba(255, 0, 0, 128)});
        for (int y = 0; y < 2; ++y)
            for (int x = 0; x < 4; ++x) img.setPixel(x, y, uint((x + y) % 3));
        const QString path = m_dir + "/palette.png";
        QVERIFY(img.save(path, "PNG"));
        QVERIFY(imageHasAlpha(path.toStdString()));
        const ImageRgba read = readImage(path.toStdString());
        QCOMPARE(read.width, 4);
        QCOMPARE(read.height, 2);
        for (int y = 0; y < 2; ++y)
            for (int x = 0; x < 4; ++x) {
                const float* p = read.at(x, y);
                const int index = (x + y) % 3;
                const float expectedAlpha = index == 0 ? 0.0f : (index == 1 ? 1.0f : 128.0f / 255.0f);
                QVERIFY2(std::fabs(p[3] - expectedAlpha) < 1e-3f, qPrintable(QString("alpha at %1,%2 = %3").arg(x).arg(y).arg(p[3])));
                if (index == 1) QVERIFY(std::fabs(p[1] - 200.0f / 255.0f) < 1e-3f && p[0] < 1e-3f);
                if (index == 2) QVERIFY2(std::fabs(p[0] - 1.0f) < 1e-3f, "colour of a half-transparent texel is not premultiplied");
            }
    }

    void greyAndSixteenBit()
    {
        QImage grey(3, 3, QImage::Format_Grayscale16);
        for (int y = 0; y < 3; ++y)
            for (int x = 0; x < 3; ++x) reinterpret_cast<quint16*>(grey.scanLine(y))[x] = quint16(x * 30000 + y);
        const QString path = m_dir + "/grey16.png";
        QVERIFY(grey.save(path, "PNG"));
        QVERIFY(!imageHasAlpha(path.toStdString()));
        const ImageRgba read = readImage(path.toStdString());
        const float* p = read.at(2, 1);
        QVERIFY(std::fabs(p[0] - 60001.0f / 65535.0f) < 1e-4f);
        QCOMPARE(p[0], p[2]);
        QCOMPARE(p[3], 1.0f);
    }

    void roundTripPngAndExr()
    {
        ImageRgba img(5, 4);
        for (int y = 0; y < 4; ++y)
            for (int x = 0; x < 5; ++x) {
                float* p = img.at(x, y);
                p[0] = float(x) / 4.0f;
                p[1] = float(y) / 3.0f;
                p[2] = 0.25f;
                p[3] = (x + y) % 2 ? 1.0f : 0.0f;
            }
        for (const char* ext : {".png", ".exr", ".tif"}) {
            const std::string path = (m_dir + "/round" + ext).toStdString();
            writeImage(path, img);
            const ImageRgba back = readImage(path);
            QCOMPARE(back.width, 5);
            for (size_t n = 0; n < img.pixels.size(); ++n)
                QVERIFY2(std::fabs(back.pixels[n] - img.pixels[n]) <= 0.5f / 255.0f + 1e-3f, ext);
        }
        // Atomic write: no temporary file is left beside the result.
        const QStringList leftovers = QDir(m_dir).entryList({".tmp.*"}, QDir::Files | QDir::Hidden);
        QVERIFY2(leftovers.isEmpty(), qPrintable(leftovers.join(",")));
    }

    void errorsNameTheFile()
    {
        const std::string missing = (m_dir + "/nope.png").toStdString();
        try {
            readImage(missing);
            QFAIL("no error for a missing file");
        } catch (const Error& e) {
            QVERIFY(QString(e.what()).contains(QString::fromStdString(missing)));
        }
        const QString garbage = m_dir + "/garbage.png";
        QFile f(garbage);
        QVERIFY(f.open(QIODevice::WriteOnly));
        f.write("\x89PNG not really");
        f.close();
        try {
            readImage(garbage.toStdString());
            QFAIL("no error for a garbage file");
        } catch (const Error& e) {
            QVERIFY(QString(e.what()).contains(garbage));
        }
        QVERIFY_THROWS_EXCEPTION(Error, writeImage((m_dir + "/x.unknownext").toStdString(), ImageRgba(2, 2)));
        QVERIFY_THROWS_EXCEPTION(Error, writeImage((m_dir + "/empty.png").toStdString(), ImageRgba()));
    }
};

QTEST_GUILESS_MAIN(TestImageIo)
#include "tst_image_io.moc"
